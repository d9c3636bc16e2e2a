// Fuzzes the REST front end's handling of a request, minus the socket: the bytes are fed to Beast's
// request parser with the server's header and body limits (as http_session.cc sets them), then the
// parsed request goes through routing (Router::Find on the REST API's routes), the query string
// (ParseQuery), the option parser (ParseDetectQuery), the JSON error body and the request log line.
// Besides memory safety it checks that an accepted option is in its documented range and that a
// request's text cannot break the one-line-per-request log format.
#include <spdlog/sinks/ostream_sink.h>

#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/parser.hpp>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>

#include "server/http/http_types.h"
#include "server/http/query_string.h"
#include "server/http/router.h"
#include "server/logging.h"
#include "server/rest_options.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

namespace beast = boost::beast;
using tod::server::http::beast_http::verb;

using tod::fuzz::Check;

// Small limits so that the fuzzer reaches them; the server's are 16 KiB and 16 MiB.
constexpr size_t kHeaderLimit = 4096;
constexpr size_t kBodyLimit = 8192;

// The routes of RestApi::Routes (http_frontend.cc), with handlers that do nothing.
tod::server::http::Router MakeRouter() {
  tod::server::http::Router router;
  const tod::server::http::RequestHandler none = [](tod::server::http::IncomingRequest,
                                                    tod::server::http::Responder) {};
  router.Add(verb::post, "/v1/detect", none);
  router.Add(verb::post, "/v1/probability-map", none);
  router.Add(verb::get, "/v1/model", none);
  router.Add(verb::get, "/v2/health/live", none);
  router.Add(verb::get, "/v2/health/ready", none);
  router.Add(verb::get, "/metrics", none);
  return router;
}

std::ostringstream& LogStream() {
  static std::ostringstream stream;
  return stream;
}

// The server's logger set up as SetUpLogging("text", "info") does, but writing to a string.
void SetUpCapturedLog() {
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(LogStream());
  auto logger = std::make_shared<spdlog::logger>("fuzz", sink);
  logger->set_pattern("%l %v");
  logger->set_level(spdlog::level::info);
  spdlog::set_default_logger(logger);
}

// The REST handler's work after routing (RestApi::Detect up to the engine).
void HandleDetect(const tod::server::http::Request& request) {
  const auto query = tod::server::http::ParseQuery(request.target());
  tod::server::InferenceRequest inference;
  std::string frame_id = "h1";
  const tod::Status status = tod::server::ParseDetectQuery(query, &inference, &frame_id);
  if (status.ok()) {
    const tod::DetectOptions& options = inference.options;
    Check(options.max_proposals >= 0 && options.max_proposals <= tod::server::kMaxRequestProposals);
    Check(options.obstacle_threshold >= 0.f && options.obstacle_threshold <= 1.f);
    // Only the two named kinds parse; any other value was refused above.
    Check(options.map_kind == tod::MapKind::kNormalized ||
          options.map_kind == tod::MapKind::kCalibrated);
  } else {
    const auto response =
        tod::server::http::JsonErrorResponse(400, "INVALID_ARGUMENT", status.message());
    Check(!response.body().empty());
  }
  // The request log line (RestApi::Detect's `finish`): one line, whatever the client sent.
  LogStream().str("");
  tod::server::LogEvent(spdlog::level::info, "detect",
                        {{"id", "h1"},
                         {"path", std::string(tod::server::http::TargetPath(request.target()))},
                         {"frame", frame_id},
                         {"error", status.message()}});
  const std::string line = LogStream().str();
  Check(!line.empty() && line.find('\n') == line.size() - 1);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  SetUpCapturedLog();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const tod::server::http::Router router = MakeRouter();

  // Also the query parser alone, on any bytes (the target of a request is already restricted by
  // Beast's parser to printable characters).
  const std::string_view raw(reinterpret_cast<const char*>(data), size);
  for (const auto& [name, value] : tod::server::http::ParseQuery(raw)) {
    Check(name.size() <= size && value.size() <= size);
  }

  beast::http::request_parser<beast::http::string_body> parser;
  parser.header_limit(kHeaderLimit);
  parser.body_limit(kBodyLimit);
  parser.eager(true);
  beast::error_code ec;
  size_t offset = 0;
  while (offset < size && !parser.is_done()) {
    const size_t used = parser.put(boost::asio::buffer(data + offset, size - offset), ec);
    if (ec == beast::http::error::need_more) break;  // a truncated request: nothing more to read
    if (ec) return 0;                                // refused as malformed or over a limit
    if (used == 0) break;
    offset += used;
  }
  if (!parser.is_header_done()) return 0;
  const tod::server::http::Request& request = parser.get();
  const tod::server::http::Router::Match match = router.Find(request.method(), request.target());
  Check((match.handler != nullptr) != match.refused.has_value());
  if (match.refused == tod::server::http::RefusalReason::kMethodNotAllowed) {
    Check(!match.allow.empty());
  }
  if (match.handler != nullptr && request.method() == verb::post) HandleDetect(request);
  return 0;
}
