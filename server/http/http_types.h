// The types the HTTP transport and the REST handlers share: Beast messages with string bodies,
// the one-shot responder a handler answers through, and the JSON error body of the REST API.
#pragma once

#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "server/core/cancellation.h"

namespace tod::server::http {

namespace beast_http = boost::beast::http;

using Request = beast_http::request<beast_http::string_body>;
using Response = beast_http::response<beast_http::string_body>;

struct IncomingRequest {
  Request message;   // header and the whole body, already bounded by the transport's limits
  std::string peer;  // client address
  // Cancelled (kClientDisconnected) when the client closes its connection before the answer.
  std::shared_ptr<Cancellation> client_gone;
};

// Decides whether a request may go on, from its header alone (before its body is read): nullopt
// to go on, or the message of a 401 refusal. Empty function: every request goes on.
using Authorizer = std::function<std::optional<std::string>(const Request& header)>;

// Answers one request. Call it exactly once, from any thread (the transport moves the write onto
// the connection's own strand); it keeps the connection alive until the response is written.
using Responder = std::function<void(Response)>;
using RequestHandler = std::function<void(IncomingRequest, Responder)>;

// {"error": {"code": ..., "http_status": ..., "message": ...}} with Content-Type application/json.
Response JsonErrorResponse(unsigned http_status, std::string_view code, std::string_view message);
// A 200 (or `http_status`) response with `body` of `content_type`.
Response ContentResponse(std::string body, std::string_view content_type,
                         unsigned http_status = 200);

}  // namespace tod::server::http
