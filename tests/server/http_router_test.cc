// The router's prefix routes next to its exact ones: exact paths win, the longest prefix takes
// the rest, and 404 / 405 (with the Allow list) are as for exact paths.
#include <gtest/gtest.h>

#include "server/http/router.h"

namespace tod::server::http {
namespace {

using beast_http::verb;

RequestHandler Named(std::string* called, std::string name) {
  return [called, name](IncomingRequest, Responder) { *called = name; };
}

TEST(HttpRouterTest, ExactRoutesWinThenTheLongestPrefix) {
  std::string called;
  Router router;
  router.Add(verb::get, "/v2/health/ready", Named(&called, "ready"));
  router.Add(verb::get, "/v2", Named(&called, "server"));
  router.AddPrefix(verb::get, "/v2/", Named(&called, "v2 prefix"));
  router.AddPrefix(verb::get, "/v2/models/", Named(&called, "models get"));
  router.AddPrefix(verb::post, "/v2/models/", Named(&called, "models post"));

  const auto call = [&](verb method, std::string_view target) {
    const Router::Match match = router.Find(method, target);
    called.clear();
    if (match.handler) (*match.handler)(IncomingRequest{}, Responder());
    return called;
  };
  EXPECT_EQ(call(verb::get, "/v2/health/ready"), "ready");
  EXPECT_EQ(call(verb::get, "/v2?x=1"), "server");
  EXPECT_EQ(call(verb::get, "/v2/models/tiny/ready"), "models get");
  EXPECT_EQ(call(verb::post, "/v2/models/tiny/infer?x=/y"), "models post");
  EXPECT_EQ(call(verb::get, "/v2/other"), "v2 prefix");

  Router::Match match = router.Find(verb::put, "/v2/models/tiny");
  EXPECT_FALSE(match.handler);
  EXPECT_EQ(match.refused, RefusalReason::kMethodNotAllowed);
  EXPECT_EQ(match.allow, "GET, POST");
  match = router.Find(verb::post, "/v2/health/ready");  // the exact route, not the /v2/ prefix
  EXPECT_EQ(match.refused, RefusalReason::kMethodNotAllowed);
  EXPECT_EQ(match.allow, "GET");
  match = router.Find(verb::get, "/v1/detect");
  EXPECT_EQ(match.refused, RefusalReason::kNotFound);
  match = router.Find(verb::get, "/v2models/x");  // starts like /v2 but is not under /v2/
  EXPECT_EQ(match.refused, RefusalReason::kNotFound);
}

TEST(HttpRouterTest, WithoutPrefixesUnknownPathsStay404) {
  std::string called;
  Router router;
  router.Add(verb::post, "/v1/detect", Named(&called, "detect"));
  EXPECT_EQ(router.Find(verb::get, "/v1/detect").refused, RefusalReason::kMethodNotAllowed);
  EXPECT_EQ(router.Find(verb::post, "/v1/detect/").refused, RefusalReason::kNotFound);
  EXPECT_TRUE(router.Find(verb::post, "/v1/detect?map=none").handler);
}

}  // namespace
}  // namespace tod::server::http
