#include "server/http/http_session.h"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/string.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/write.hpp>
#include <exception>

namespace tod::server::http {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
using namespace std::chrono_literals;

constexpr size_t kReadChunk = 16 * 1024;
// Lingering close: how long and how much we keep reading (and discarding) after our answer.
constexpr auto kLingerTime = 2s;
constexpr uint64_t kLingerBytes = 64u << 20;

bool IsPostOrPut(beast_http::verb method) {
  return method == beast_http::verb::post || method == beast_http::verb::put ||
         method == beast_http::verb::patch;
}

// The client went away (or reset) rather than sending something wrong.
bool IsDisconnect(beast::error_code ec) {
  return ec == beast_http::error::end_of_stream || ec == beast_http::error::partial_message ||
         ec == net::error::eof || ec == net::error::connection_reset ||
         ec == net::error::broken_pipe || ec == net::error::connection_aborted;
}

std::string Milliseconds(std::chrono::milliseconds ms) { return std::to_string(ms.count()); }

}  // namespace

HttpSession::HttpSession(Socket socket, std::string peer, ConnectionLimiter::Ticket ticket,
                         SessionContext& context)
    : socket_(std::move(socket)),
      deadline_(socket_.get_executor()),
      peer_(std::move(peer)),
      ticket_(std::move(ticket)),
      context_(context),
      buffer_(context.limits.max_header_bytes + kReadChunk) {
  continue_.version(11);
  continue_.result(beast_http::status::continue_);
}

void HttpSession::Start() {
  net::dispatch(socket_.get_executor(), [self = shared_from_this()] { self->WaitForRequest(); });
}

void HttpSession::StartRefused(RefusalReason reason, std::string message) {
  net::dispatch(socket_.get_executor(),
                [self = shared_from_this(), reason, message = std::move(message)]() mutable {
                  self->RefuseAndClose(reason, std::move(message));
                });
}

void HttpSession::ArmDeadline(Clock::time_point when) {
  expired_ = false;
  deadline_.expires_at(when);
  deadline_.async_wait([self = shared_from_this()](beast::error_code ec) {
    // A wait that completes after the deadline moved (or was cancelled) is stale.
    if (ec || self->deadline_.expiry() > Clock::now()) return;
    self->expired_ = true;
    beast::error_code ignored;
    self->socket_.cancel(ignored);
  });
}

bool HttpSession::TakeExpired() { return std::exchange(expired_, false); }

void HttpSession::WaitForRequest() {
  if (context_.stopping) {
    LingeringClose();
    return;
  }
  if (buffer_.size() > 0) {  // the client already sent (part of) the next request
    BeginRequest();
    return;
  }
  // Idle: nothing of a request yet. The request deadline starts with its first byte.
  ArmDeadline(context_.limits.idle_timeout);
  socket_.async_read_some(
      buffer_.prepare(kReadChunk), [self = shared_from_this()](beast::error_code ec, size_t bytes) {
        if (self->TakeExpired()) {
          // A kept-alive connection going quiet is normal; a new one that never speaks is not.
          if (self->requests_ == 0) {
            self->Report(RefusalReason::kIdleTimeout,
                         "no request within " + Milliseconds(self->context_.limits.idle_timeout) +
                             " ms of connecting");
          }
          self->Close();
          return;
        }
        if (ec) {
          self->Close();
          return;
        }
        self->buffer_.commit(bytes);
        self->BeginRequest();
      });
}

void HttpSession::BeginRequest() {
  const HttpLimits& limits = context_.limits;
  ArmDeadline(limits.request_timeout);  // one deadline for the whole request, header and body
  target_.clear();
  parser_.emplace();
  parser_->header_limit(limits.max_header_bytes);
  parser_->body_limit(limits.max_body_bytes);
  beast_http::async_read_header(
      socket_, buffer_, *parser_,
      [self = shared_from_this()](beast::error_code ec, size_t) { self->OnHeader(ec); });
}

void HttpSession::OnHeader(beast::error_code ec) {
  if (ec) {
    OnReadError(ec);
    return;
  }
  const Request& request = parser_->get();
  target_ = std::string(request.target());
  // Routed now so that a wrong method or path is answered as such (405 / 404, after the body is
  // read within the limits) rather than as a missing length.
  match_ = context_.router.Find(request.method(), request.target());
  const boost::optional<uint64_t> length = parser_->content_length();
  if (!match_.refused && IsPostOrPut(request.method()) && !length && !parser_->chunked()) {
    RefuseAndClose(RefusalReason::kLengthRequired, std::string(request.method_string()) +
                                                       " needs a Content-Length or a chunked body");
    return;
  }
  // Charge what this body may occupy before any of it is read: the declared length (already
  // checked against the body limit by the parser), or the whole limit for a chunked body.
  const uint64_t charge =
      length ? *length : (parser_->chunked() ? context_.limits.max_body_bytes : 0);
  if (charge > 0) {
    std::optional<ByteBudget::Lease> lease = context_.budget.TryAcquire(charge);
    if (!lease) {
      RefuseAndClose(RefusalReason::kBufferBudget,
                     "server busy: too many request bodies in flight; retry after a short pause");
      return;
    }
    body_lease_ = std::move(*lease);
  }
  if (parser_->is_done()) {
    Dispatch();
    return;
  }
  if (beast::iequals(request[beast_http::field::expect], "100-continue")) {
    // curl and others wait for this before sending a large body.
    continue_.version(request.version());
    beast_http::async_write(socket_, continue_,
                            [self = shared_from_this()](beast::error_code write_ec, size_t) {
                              if (self->TakeExpired()) {
                                self->OnReadError(beast::error::timeout);
                              } else if (write_ec) {
                                self->Close();
                              } else {
                                self->ReadBody();
                              }
                            });
    return;
  }
  ReadBody();
}

void HttpSession::ReadBody() {
  beast_http::async_read(
      socket_, buffer_, *parser_,
      [self = shared_from_this()](beast::error_code ec, size_t) { self->OnBody(ec); });
}

void HttpSession::OnBody(beast::error_code ec) {
  if (ec) {
    OnReadError(ec);
    return;
  }
  Dispatch();
}

void HttpSession::OnReadError(beast::error_code ec) {
  const HttpLimits& limits = context_.limits;
  if (TakeExpired() || ec == beast::error::timeout) {
    RefuseAndClose(RefusalReason::kReadTimeout, "the request did not arrive completely within " +
                                                    Milliseconds(limits.request_timeout) + " ms");
  } else if (ec == beast_http::error::body_limit) {
    RefuseAndClose(
        RefusalReason::kBodyTooLarge,
        "request body is over the limit of " + std::to_string(limits.max_body_bytes) + " bytes");
  } else if (ec == beast_http::error::header_limit || ec == beast_http::error::buffer_overflow) {
    RefuseAndClose(RefusalReason::kHeaderTooLarge,
                   "request line and headers are over the limit "
                   "of " +
                       std::to_string(limits.max_header_bytes) + " bytes");
  } else if (IsDisconnect(ec) || ec == net::error::operation_aborted) {
    Close();  // the client left; there is nobody to answer
  } else {
    RefuseAndClose(RefusalReason::kMalformedRequest, "malformed HTTP request: " + ec.message());
  }
}

void HttpSession::Dispatch() {
  deadline_.cancel();  // the handler's own deadlines (queue, engine) apply from here
  Request request = parser_->release();
  parser_.reset();
  version_ = request.version();
  keep_alive_ = request.keep_alive();
  const Router::Match match = std::exchange(match_, Router::Match());
  if (match.refused) {
    const RefusalReason reason = *match.refused;
    const std::string message =
        reason == RefusalReason::kNotFound
            ? "no such endpoint: " + std::string(TargetPath(request.target()))
            : std::string(request.method_string()) + " is not allowed on " +
                  std::string(TargetPath(request.target())) + "; allowed: " + match.allow;
    Report(reason, message);
    Response response =
        JsonErrorResponse(RefusalHttpStatus(reason), RefusalCodeName(reason), message);
    if (!match.allow.empty()) response.set(beast_http::field::allow, match.allow);
    response.version(version_);
    response.keep_alive(keep_alive_);
    Write(std::move(response), keep_alive_ ? After::kKeepAlive : After::kClose);
    return;
  }
  awaiting_handler_ = true;
  in_flight_ = true;
  ++context_.in_flight;
  Responder respond = [self = shared_from_this()](Response response) {
    net::post(self->socket_.get_executor(), [self, response = std::move(response)]() mutable {
      self->OnHandlerResponse(std::move(response));
    });
  };
  try {
    (*match.handler)(IncomingRequest{std::move(request), peer_}, std::move(respond));
  } catch (const std::exception& e) {
    Report(RefusalReason::kInternal, std::string("handler failed: ") + e.what());
    OnHandlerResponse(JsonErrorResponse(500, "INTERNAL", "the request could not be handled"));
  }
}

void HttpSession::OnHandlerResponse(Response response) {
  if (!awaiting_handler_) return;  // answered already (a handler threw after answering)
  awaiting_handler_ = false;       // still in flight until written (see OnWritten)
  const bool keep_alive = keep_alive_ && !context_.stopping && response.keep_alive();
  response.version(version_);
  response.keep_alive(keep_alive);
  Write(std::move(response), keep_alive ? After::kKeepAlive : After::kClose);
}

void HttpSession::Report(RefusalReason reason, std::string message) const {
  if (context_.observer.on_refusal) {
    context_.observer.on_refusal(Refusal{reason, std::move(message), peer_, target_});
  }
}

void HttpSession::RefuseAndClose(RefusalReason reason, std::string message) {
  const unsigned status = RefusalHttpStatus(reason);
  Report(reason, message);
  if (status == 0) {
    Close();
    return;
  }
  Response response = JsonErrorResponse(status, RefusalCodeName(reason), message);
  if (status == 503) {
    response.set(beast_http::field::retry_after, std::to_string(context_.retry_after_s));
  }
  response.version(11);
  response.keep_alive(false);  // the rest of the request is unread: no way to find the next one
  Write(std::move(response), After::kClose);
}

void HttpSession::Write(Response response, After after) {
  response_.emplace(std::move(response));
  response_->prepare_payload();
  ArmDeadline(context_.limits.write_timeout);
  beast_http::async_write(socket_, *response_,
                          [self = shared_from_this(), after](beast::error_code ec, size_t) {
                            self->OnWritten(ec, after);
                          });
}

void HttpSession::OnWritten(beast::error_code ec, After after) {
  response_.reset();
  LeaveInFlight();
  body_lease_ = ByteBudget::Lease();  // the request body is gone
  if (TakeExpired()) {
    Report(RefusalReason::kWriteTimeout, "the client did not read its response within " +
                                             Milliseconds(context_.limits.write_timeout) + " ms");
    Close();
    return;
  }
  if (ec) {
    Close();
    return;
  }
  ++requests_;
  if (after == After::kKeepAlive) {
    WaitForRequest();
  } else {
    LingeringClose();
  }
}

void HttpSession::LingeringClose() {
  beast::error_code ec;
  socket_.shutdown(Socket::shutdown_send, ec);
  if (ec) {
    Close();
    return;
  }
  drain_.resize(kReadChunk);
  ArmDeadline(kLingerTime);
  Drain();
}

void HttpSession::Drain() {
  socket_.async_read_some(net::buffer(drain_),
                          [self = shared_from_this()](beast::error_code ec, size_t bytes) {
                            self->drained_ += bytes;
                            if (ec || self->TakeExpired() || self->drained_ > kLingerBytes) {
                              self->Close();
                              return;
                            }
                            self->Drain();
                          });
}

void HttpSession::Close() {
  beast::error_code ignored;
  deadline_.cancel();
  socket_.shutdown(Socket::shutdown_both, ignored);
  socket_.close(ignored);
  awaiting_handler_ = false;  // a late answer finds the socket closed and is dropped
  LeaveInFlight();
}

void HttpSession::LeaveInFlight() {
  if (std::exchange(in_flight_, false)) --context_.in_flight;
}

}  // namespace tod::server::http
