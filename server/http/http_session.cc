#include "server/http/http_session.h"

#include <algorithm>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/string.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/read.hpp>
#include <boost/beast/http/write.hpp>
#include <exception>
#include <utility>

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

template <class Stream>
HttpSession<Stream>::HttpSession(Stream stream, std::string peer, ConnectionLimiter::Ticket ticket,
                                 SessionContext& context)
    : stream_(std::move(stream)),
      deadline_(stream_.get_executor()),
      peer_(std::move(peer)),
      ticket_(std::move(ticket)),
      context_(context),
      buffer_(context.limits.max_header_bytes + kReadChunk) {
  continue_.version(11);
  continue_.result(beast_http::status::continue_);
}

template <class Stream>
void HttpSession<Stream>::Start() {
  net::dispatch(stream_.get_executor(), [self = this->shared_from_this()] {
    self->Handshake([self] { self->WaitForRequest(); });
  });
}

template <class Stream>
void HttpSession<Stream>::StartRefused(RefusalReason reason, std::string message) {
  net::dispatch(stream_.get_executor(),
                [self = this->shared_from_this(), reason, message = std::move(message)]() mutable {
                  // Over TLS the refusal can only be answered after the handshake.
                  self->Handshake([self, reason, message = std::move(message)]() mutable {
                    self->RefuseAndClose(reason, std::move(message));
                  });
                });
}

template <class Stream>
void HttpSession<Stream>::Handshake(std::function<void()> next) {
  if constexpr (!kTls) {
    next();
  } else {
    ArmDeadline(context_.limits.request_timeout);
    stream_.async_handshake(
        net::ssl::stream_base::server,
        [self = this->shared_from_this(), next = std::move(next)](beast::error_code ec) {
          if (self->TakeExpired()) {
            self->Report(RefusalReason::kTlsHandshake,
                         "TLS handshake did not finish within " +
                             Milliseconds(self->context_.limits.request_timeout) + " ms");
            self->Close();
          } else if (ec) {
            self->Report(RefusalReason::kTlsHandshake, "TLS handshake failed: " + ec.message());
            self->Close();
          } else {
            next();
          }
        });
  }
}

template <class Stream>
void HttpSession<Stream>::ArmDeadline(Clock::time_point when) {
  expired_ = false;
  deadline_.expires_at(when);
  deadline_.async_wait([self = this->shared_from_this()](beast::error_code ec) {
    // A wait that completes after the deadline moved (or was cancelled) is stale.
    if (ec || self->deadline_.expiry() > Clock::now()) return;
    self->expired_ = true;
    beast::error_code ignored;
    self->socket().cancel(ignored);
  });
}

template <class Stream>
bool HttpSession<Stream>::TakeExpired() {
  return std::exchange(expired_, false);
}

template <class Stream>
void HttpSession<Stream>::WaitForRequest() {
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
  stream_.async_read_some(buffer_.prepare(kReadChunk), [self = this->shared_from_this()](
                                                           beast::error_code ec, size_t bytes) {
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

template <class Stream>
void HttpSession<Stream>::BeginRequest() {
  const HttpLimits& limits = context_.limits;
  ArmDeadline(limits.request_timeout);  // one deadline for the whole request, header and body
  target_.clear();
  parser_.emplace();
  parser_->header_limit(limits.max_header_bytes);
  parser_->body_limit(limits.max_body_bytes);
  beast_http::async_read_header(
      stream_, buffer_, *parser_,
      [self = this->shared_from_this()](beast::error_code ec, size_t) { self->OnHeader(ec); });
}

template <class Stream>
void HttpSession<Stream>::OnHeader(beast::error_code ec) {
  if (ec) {
    OnReadError(ec);
    return;
  }
  const Request& request = parser_->get();
  target_ = std::string(request.target());
  // Routed now so that a wrong method or path is answered as such (405 / 404, after the body is
  // read within the limits) rather than as a missing length.
  match_ = context_.router.Find(request.method(), request.target());
  // Authentication before the body: a client without a valid token costs no body bytes.
  if (!match_.refused && context_.authorizer) {
    if (std::optional<std::string> refused = context_.authorizer(request)) {
      RefuseAndClose(RefusalReason::kUnauthenticated, std::move(*refused));
      return;
    }
  }
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
    beast_http::async_write(stream_, continue_,
                            [self = this->shared_from_this()](beast::error_code write_ec, size_t) {
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

template <class Stream>
void HttpSession<Stream>::ReadBody() {
  beast_http::async_read(
      stream_, buffer_, *parser_,
      [self = this->shared_from_this()](beast::error_code ec, size_t) { self->OnBody(ec); });
}

template <class Stream>
void HttpSession<Stream>::OnBody(beast::error_code ec) {
  if (ec) {
    OnReadError(ec);
    return;
  }
  Dispatch();
}

template <class Stream>
void HttpSession<Stream>::OnReadError(beast::error_code ec) {
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

template <class Stream>
void HttpSession<Stream>::Dispatch() {
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
  client_gone_ = std::make_shared<Cancellation>();
  Responder respond = [self = this->shared_from_this()](Response response) {
    net::post(self->stream_.get_executor(), [self, response = std::move(response)]() mutable {
      self->OnHandlerResponse(std::move(response));
    });
  };
  try {
    (*match.handler)(IncomingRequest{std::move(request), peer_, client_gone_}, std::move(respond));
  } catch (const std::exception& e) {
    Report(RefusalReason::kInternal, std::string("handler failed: ") + e.what());
    OnHandlerResponse(JsonErrorResponse(500, "INTERNAL", "the request could not be handled"));
  }
  // Answers arrive through a post to this strand, never inline: the handler is still at work.
  // Bytes of a next request already buffered (a pipelining client) say the client is there, and
  // a watch read then must not start: after the answer it would be the only read pending, and
  // the buffered request would wait for bytes that never come (HTTP/1.1 answers in order: the
  // client waits for ours first). Without a watch, OnWritten starts the buffered request.
  if (awaiting_handler_ && buffer_.size() == 0) Watch();
}

template <class Stream>
void HttpSession<Stream>::Watch() {
  watching_ = true;
  stream_.async_read_some(buffer_.prepare(kReadChunk),
                          [self = this->shared_from_this()](beast::error_code ec, size_t bytes) {
                            self->OnWatch(ec, bytes);
                          });
}

template <class Stream>
void HttpSession<Stream>::OnWatch(beast::error_code ec, size_t bytes) {
  watching_ = false;
  if (closed_) return;
  if (!ec) buffer_.commit(bytes);
  if (awaiting_handler_) {
    if (ec) {  // EOF or reset while the request is handled: nobody will read the answer
      client_gone_->Cancel(CancelReason::kClientDisconnected);
      Close();
    }
    // Bytes of a next (pipelined) request: the client is there; they wait in buffer_.
    return;
  }
  if (writing_) return;  // OnWritten goes on (and sees a broken connection itself)
  // The answer is written and this read has been the wait for the next request.
  if (TakeExpired() || ec) {
    Close();
    return;
  }
  BeginRequest();
}

template <class Stream>
void HttpSession<Stream>::OnHandlerResponse(Response response) {
  if (!awaiting_handler_) return;  // answered already (a handler threw after answering)
  awaiting_handler_ = false;       // still in flight until written (see OnWritten)
  const bool keep_alive = keep_alive_ && !context_.stopping && response.keep_alive();
  response.version(version_);
  response.keep_alive(keep_alive);
  Write(std::move(response), keep_alive ? After::kKeepAlive : After::kClose);
}

template <class Stream>
void HttpSession<Stream>::Report(RefusalReason reason, std::string message) const {
  if (context_.observer.on_refusal) {
    context_.observer.on_refusal(Refusal{reason, std::move(message), peer_, target_});
  }
}

template <class Stream>
void HttpSession<Stream>::RefuseAndClose(RefusalReason reason, std::string message) {
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
  if (reason == RefusalReason::kUnauthenticated) {
    response.set(beast_http::field::www_authenticate, "Bearer");
  }
  response.version(11);
  response.keep_alive(false);  // the rest of the request is unread: no way to find the next one
  Write(std::move(response), After::kClose);
}

template <class Stream>
void HttpSession<Stream>::Write(Response response, After after) {
  writing_ = true;
  response_.emplace(std::move(response));
  response_->prepare_payload();
  ArmDeadline(context_.limits.write_timeout);
  beast_http::async_write(stream_, *response_,
                          [self = this->shared_from_this(), after](beast::error_code ec, size_t) {
                            self->OnWritten(ec, after);
                          });
}

template <class Stream>
void HttpSession<Stream>::OnWritten(beast::error_code ec, After after) {
  writing_ = false;
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
  if (watching_) {
    // The watch read is still open: it becomes the idle wait for the next request (a second
    // read cannot be started beside it). Its bytes, if any, start that request in OnWatch.
    if (after == After::kKeepAlive && !context_.stopping) {
      ArmDeadline(context_.limits.idle_timeout);
    } else {
      Close();  // the request was read whole: nothing to linger for
    }
    return;
  }
  if (after == After::kKeepAlive) {
    WaitForRequest();
  } else {
    LingeringClose();
  }
}

template <class Stream>
void HttpSession<Stream>::LingeringClose() {
  beast::error_code ec;
  socket().shutdown(Socket::shutdown_send, ec);
  if (ec) {
    Close();
    return;
  }
  drain_.resize(kReadChunk);
  ArmDeadline(kLingerTime);
  Drain();
}

template <class Stream>
void HttpSession<Stream>::Drain() {
  socket().async_read_some(net::buffer(drain_),
                           [self = this->shared_from_this()](beast::error_code ec, size_t bytes) {
                             self->drained_ += bytes;
                             if (ec || self->TakeExpired() || self->drained_ > kLingerBytes) {
                               self->Close();
                               return;
                             }
                             self->Drain();
                           });
}

template <class Stream>
void HttpSession<Stream>::Close() {
  closed_ = true;
  beast::error_code ignored;
  deadline_.cancel();
  socket().shutdown(Socket::shutdown_both, ignored);
  socket().close(ignored);
  awaiting_handler_ = false;  // a late answer finds the socket closed and is dropped
  LeaveInFlight();
}

template <class Stream>
void HttpSession<Stream>::LeaveInFlight() {
  if (std::exchange(in_flight_, false)) --context_.in_flight;
}

template class HttpSession<PlainStream>;
template class HttpSession<TlsStream>;

}  // namespace tod::server::http
