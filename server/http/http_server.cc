#include "server/http/http_server.h"

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "server/http/connection_limiter.h"

namespace tod::server::http {
namespace {

namespace net = boost::asio;
using tcp = net::ip::tcp;
using namespace std::chrono_literals;

// "::ffff:127.0.0.1" and "127.0.0.1" are the same client.
std::string ClientAddress(const tcp::socket& socket) {
  boost::system::error_code ec;
  const tcp::endpoint endpoint = socket.remote_endpoint(ec);
  if (ec) return "unknown";
  net::ip::address address = endpoint.address();
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    address = net::ip::make_address_v4(net::ip::v4_mapped, address.to_v6());
  }
  return address.to_string();
}

}  // namespace

struct HttpServer::Impl {
  Impl(HttpServerOptions options, Router router, HttpObserver observer)
      : context(options.limits, std::move(router), std::move(observer), options.retry_after_s,
                std::move(options.authorizer)),
        limiter(options.limits.max_connections, options.limits.max_connections_per_client,
                context.observer.on_open_connections),
        tls(std::move(options.tls)),
        io_threads(options.io_threads) {}

  void Accept() {
    acceptor.async_accept(net::make_strand(io),
                          [this](boost::system::error_code ec, tcp::socket socket) {
                            if (!acceptor.is_open()) return;
                            if (ec) {
                              // Out of file descriptors and similar: back off instead of spinning
                              // on accept.
                              retry.expires_after(100ms);
                              retry.async_wait([this](boost::system::error_code wait_ec) {
                                if (!wait_ec) Accept();
                              });
                              return;
                            }
                            Admit(std::move(socket));
                            Accept();
                          });
  }

  void Admit(tcp::socket socket) {
    const std::string client = ClientAddress(socket);
    ConnectionLimiter::Admission admission = limiter.TryAcquire(client);
    if (tls) {
      Serve(std::make_shared<HttpSession<TlsStream>>(TlsStream(std::move(socket), *tls), client,
                                                     std::move(admission.ticket), context),
            client, admission.refused);
    } else {
      Serve(std::make_shared<HttpSession<PlainStream>>(std::move(socket), client,
                                                       std::move(admission.ticket), context),
            client, admission.refused);
    }
  }

  template <class Session>
  void Serve(const std::shared_ptr<Session>& session, const std::string& client,
             std::optional<RefusalReason> refused) {
    if (!refused) {
      session->Start();
      return;
    }
    const HttpLimits& limits = context.limits;
    const std::string message =
        *refused == RefusalReason::kTooManyConnections
            ? "server busy: " + std::to_string(limits.max_connections) + " connections are open"
            : "too many connections from " + client + " (limit " +
                  std::to_string(limits.max_connections_per_client) + ")";
    session->StartRefused(*refused, message);
  }

  // Declared first so that it outlives `io`, whose destruction destroys the connections.
  SessionContext context;
  ConnectionLimiter limiter;
  const std::shared_ptr<net::ssl::context> tls;  // null: plain HTTP
  net::io_context io;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> work;
  tcp::acceptor acceptor{net::make_strand(io)};
  net::steady_timer retry{acceptor.get_executor()};
  const int io_threads;
  std::vector<std::thread> threads;
  int port = 0;
};

HttpServer::HttpServer(HttpServerOptions options, Router router, HttpObserver observer)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(router), std::move(observer))) {}

HttpServer::~HttpServer() { Stop(); }

Status HttpServer::Bind(const std::string& host, int port) {
  boost::system::error_code ec;
  tcp::resolver resolver(impl_->io);
  const auto endpoints = resolver.resolve(
      host, std::to_string(port), tcp::resolver::passive | tcp::resolver::numeric_service, ec);
  if (ec || endpoints.empty()) {
    return Status::Unavailable("http: cannot resolve " + host + ": " + ec.message());
  }
  const tcp::endpoint endpoint = endpoints.begin()->endpoint();
  tcp::acceptor& acceptor = impl_->acceptor;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    acceptor.close();
    return Status::Unavailable("http: cannot bind " + host + ":" + std::to_string(port) + " (" +
                               ec.message() + ")");
  }
  impl_->port = acceptor.local_endpoint().port();
  return Status::Ok();
}

int HttpServer::port() const { return impl_->port; }

void HttpServer::Start() {
  if (!impl_->threads.empty()) return;
  impl_->work.emplace(impl_->io.get_executor());
  net::post(impl_->acceptor.get_executor(), [impl = impl_.get()] { impl->Accept(); });
  for (int i = 0; i < impl_->io_threads; ++i) {
    impl_->threads.emplace_back([impl = impl_.get()] { impl->io.run(); });
  }
}

void HttpServer::Stop(std::chrono::milliseconds grace) {
  if (impl_->threads.empty()) return;
  impl_->context.stopping = true;
  net::post(impl_->acceptor.get_executor(), [impl = impl_.get()] {
    boost::system::error_code ignored;
    impl->acceptor.close(ignored);
    impl->retry.cancel();
  });
  // Answers the engine has produced are still being written: give them time to reach clients.
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (impl_->context.in_flight > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(5ms);
  }
  impl_->work.reset();
  impl_->io.stop();
  for (std::thread& thread : impl_->threads) thread.join();
  impl_->threads.clear();
}

}  // namespace tod::server::http
