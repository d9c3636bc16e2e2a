// One client connection: reads requests under the limits, hands each complete request to its
// route, writes the answer, and closes when a limit is hit. Everything is asynchronous on the
// connection's strand, so a slow or stuck client costs a socket and a few kilobytes, never a
// thread. Every way a request can fail before a handler sees it is a Refusal: logged, counted,
// and answered with a JSON error when an answer is possible.
//
// Deadlines come from one timer per connection instead of Beast's tcp_stream timeouts, because
// tcp_stream closes the socket when its timer fires, which would make the 408 impossible.
//
// The session is a template over its stream: a plain TCP socket, or TLS over it
// (asio::ssl::stream), which only adds the handshake before the first request. HTTP reads and
// writes go through the stream; cancelling, half-closing, lingering and closing act on the TCP
// socket underneath.
//
// While a handler works on a request, the session keeps one read open on the connection: when it
// ends in EOF or an error, the client has gone, and the request's `client_gone` Cancellation is
// cancelled so that its work stops at the next stage boundary. (A client that half-closes its
// sending side after the request therefore counts as gone; HTTP/1.1 clients do not do that.)
#pragma once

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/stream.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/stream_traits.hpp>
#include <boost/beast/http/empty_body.hpp>
#include <boost/beast/http/parser.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "server/http/byte_budget.h"
#include "server/http/connection_limiter.h"
#include "server/http/http_limits.h"
#include "server/http/http_types.h"
#include "server/http/refusal.h"
#include "server/http/router.h"

namespace tod::server::http {

struct HttpObserver {
  std::function<void(const Refusal&)> on_refusal;  // log and count it
  std::function<void(int)> on_open_connections;    // gauge
};

using PlainStream = boost::asio::ip::tcp::socket;
using TlsStream = boost::asio::ssl::stream<boost::asio::ip::tcp::socket>;

// What all connections of one server share; the server owns it and outlives every connection.
struct SessionContext {
  SessionContext(HttpLimits limits_in, Router router_in, HttpObserver observer_in, int retry_after,
                 Authorizer authorizer_in = {})
      : limits(limits_in),
        router(std::move(router_in)),
        observer(std::move(observer_in)),
        authorizer(std::move(authorizer_in)),
        budget(limits_in.max_buffered_bytes),
        retry_after_s(retry_after) {}

  const HttpLimits limits;
  const Router router;
  const HttpObserver observer;
  const Authorizer authorizer;  // asked for every routed request, from its header
  ByteBudget budget;
  const int retry_after_s;            // Retry-After of the 503 refusals
  std::atomic<int> in_flight{0};      // requests handed to a handler and not yet answered
  std::atomic<bool> stopping{false};  // finish the current response, then close
};

template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
 public:
  using Socket = boost::asio::ip::tcp::socket;
  static constexpr bool kTls = std::is_same_v<Stream, TlsStream>;

  HttpSession(Stream stream, std::string peer, ConnectionLimiter::Ticket ticket,
              SessionContext& context);
  HttpSession(const HttpSession&) = delete;
  HttpSession& operator=(const HttpSession&) = delete;

  // Serves requests until the client leaves, a limit is hit or the server stops.
  void Start();
  // The connection was refused at accept (`reason`): answer 503 and close.
  void StartRefused(RefusalReason reason, std::string message);

 private:
  using Clock = std::chrono::steady_clock;
  using Parser = beast_http::request_parser<beast_http::string_body>;
  enum class After { kKeepAlive, kClose };

  // TLS: the handshake, under the request deadline, then `next`; plain TCP: `next` at once.
  void Handshake(std::function<void()> next);
  void WaitForRequest();
  void BeginRequest();
  void OnHeader(boost::beast::error_code ec);
  void ReadBody();
  void OnBody(boost::beast::error_code ec);
  void OnReadError(boost::beast::error_code ec);
  void Dispatch();
  void OnHandlerResponse(Response response);
  // The read that notices a client leaving while its request is handled; after the answer is
  // written it doubles as the wait for the next request (see OnWatch).
  void Watch();
  void OnWatch(boost::beast::error_code ec, size_t bytes);
  Socket& socket() { return boost::beast::get_lowest_layer(stream_); }

  // Logs and counts; then answers with the refusal's status (when it has one) and closes.
  void RefuseAndClose(RefusalReason reason, std::string message);
  void Report(RefusalReason reason, std::string message) const;
  void Write(Response response, After after);
  void OnWritten(boost::beast::error_code ec, After after);
  // Half-closes, then reads and discards what the client still sends (bounded), so the client
  // sees our answer instead of a connection reset caused by unread bytes.
  void LingeringClose();
  void Drain();
  void Close();
  void LeaveInFlight();

  // One deadline at a time; when it passes, pending I/O is cancelled and `expired_` is set.
  void ArmDeadline(Clock::time_point when);
  void ArmDeadline(Clock::duration from_now) { ArmDeadline(Clock::now() + from_now); }
  bool TakeExpired();

  Stream stream_;
  boost::asio::steady_timer deadline_;
  bool expired_ = false;
  const std::string peer_;
  ConnectionLimiter::Ticket ticket_;  // released when the connection object goes away
  SessionContext& context_;

  boost::beast::flat_buffer buffer_;  // bounded: header limit plus one read
  std::optional<Parser> parser_;
  ByteBudget::Lease body_lease_;
  beast_http::response<beast_http::empty_body> continue_;  // "100 Continue"
  std::optional<Response> response_;                       // being written
  std::vector<char> drain_;                                // lingering close only
  uint64_t drained_ = 0;
  std::string target_;
  Router::Match match_;  // of the request being read
  unsigned version_ = 11;
  bool keep_alive_ = true;
  bool awaiting_handler_ = false;  // a handler has the request and has not answered
  bool in_flight_ = false;         // counted in context_.in_flight until the answer is written
  bool watching_ = false;          // the Watch() read is pending
  bool writing_ = false;           // a response is being written
  bool closed_ = false;
  std::shared_ptr<Cancellation> client_gone_;  // of the request a handler has
  int requests_ = 0;                           // answered on this connection
};

extern template class HttpSession<PlainStream>;
extern template class HttpSession<TlsStream>;

}  // namespace tod::server::http
