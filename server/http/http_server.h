// The HTTP/1.1 transport: a listening socket and a small fixed set of I/O threads running
// asynchronous connections (Boost.Beast over Boost.Asio). Connections are admitted through the
// connection limiter; requests are read under HttpLimits and routed; refusals go to the observer.
// Handlers must not block: they answer through their Responder, from any thread.
#pragma once

#include <boost/asio/ssl/context.hpp>
#include <chrono>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "server/http/http_limits.h"
#include "server/http/http_session.h"
#include "server/http/router.h"

namespace tod::server::http {

// HTTPS when `tls` is set (the context holds the certificate, key and, for mutual TLS, the client
// CA and verify mode); `authorizer` (optional) is asked for every routed request's header.
struct HttpServerOptions {
  HttpLimits limits;
  int io_threads = 2;
  int retry_after_s = 1;
  std::shared_ptr<boost::asio::ssl::context> tls;
  Authorizer authorizer;
};

class HttpServer {
 public:
  HttpServer(HttpServerOptions options, Router router, HttpObserver observer);
  // Stops (see Stop). Requests still held by handlers must have been answered or dropped.
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds and listens (port 0: any free port; then see port()).
  Status Bind(const std::string& host, int port);
  int port() const;
  void Start();
  // Stops accepting, waits up to `grace` for requests being handled to be answered and written,
  // then stops the I/O threads and closes every connection.
  void Stop(std::chrono::milliseconds grace = std::chrono::seconds(5));

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tod::server::http
