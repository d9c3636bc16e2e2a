// Unit tests of the REST transport's parts: connection caps, the body-byte budget, routing,
// query strings and the REST option ranges.
#include <gtest/gtest.h>

#include <limits>

#include "server/http/byte_budget.h"
#include "server/http/connection_limiter.h"
#include "server/http/query_string.h"
#include "server/http/router.h"
#include "server/rest_options.h"

namespace tod::server::http {
namespace {

TEST(ConnectionLimiterTest, CapsTotalAndPerClientAndTicketsGiveSlotsBack) {
  int reported = -1;
  ConnectionLimiter limiter(3, 2, [&](int open) { reported = open; });
  ConnectionLimiter::Admission a1 = limiter.TryAcquire("a");
  ConnectionLimiter::Admission a2 = limiter.TryAcquire("a");
  EXPECT_FALSE(a1.refused);
  EXPECT_FALSE(a2.refused);
  EXPECT_EQ(limiter.TryAcquire("a").refused, RefusalReason::kTooManyConnectionsPerClient);
  ConnectionLimiter::Admission b1 = limiter.TryAcquire("b");
  EXPECT_FALSE(b1.refused);
  EXPECT_EQ(limiter.TryAcquire("c").refused, RefusalReason::kTooManyConnections);
  EXPECT_EQ(limiter.open(), 3);
  EXPECT_EQ(reported, 3);
  {
    const ConnectionLimiter::Ticket moved = std::move(a1.ticket);  // moving keeps one slot
    EXPECT_EQ(limiter.open(), 3);
  }
  EXPECT_EQ(limiter.open(), 2);
  EXPECT_EQ(reported, 2);
  EXPECT_FALSE(limiter.TryAcquire("a").refused);  // released at once, ticket dropped
  EXPECT_EQ(limiter.open(), 2);
}

TEST(ByteBudgetTest, LeasesAreBoundedAndReturned) {
  ByteBudget budget(100);
  std::optional<ByteBudget::Lease> a = budget.TryAcquire(60);
  ASSERT_TRUE(a);
  EXPECT_FALSE(budget.TryAcquire(41));
  EXPECT_FALSE(budget.TryAcquire(std::numeric_limits<uint64_t>::max()));  // no overflow
  std::optional<ByteBudget::Lease> b = budget.TryAcquire(40);
  ASSERT_TRUE(b);
  EXPECT_EQ(budget.in_use(), 100u);
  a.reset();
  EXPECT_EQ(budget.in_use(), 40u);
  ByteBudget::Lease c = std::move(*b);
  b.reset();
  EXPECT_EQ(budget.in_use(), 40u);
  c = ByteBudget::Lease();
  EXPECT_EQ(budget.in_use(), 0u);
}

TEST(RouterTest, FindsRoutesAndExplainsMisses) {
  Router router;
  int called = 0;
  router.Add(beast_http::verb::post, "/v1/detect", [&](IncomingRequest, Responder) { ++called; });
  router.Add(beast_http::verb::get, "/v1/detect", [](IncomingRequest, Responder) {});
  router.Add(beast_http::verb::get, "/v2/health/live", [](IncomingRequest, Responder) {});
  const Router::Match hit = router.Find(beast_http::verb::post, "/v1/detect?map=none");
  ASSERT_NE(hit.handler, nullptr);
  (*hit.handler)(IncomingRequest{}, Responder());
  EXPECT_EQ(called, 1);
  const Router::Match wrong = router.Find(beast_http::verb::put, "/v1/detect");
  EXPECT_EQ(wrong.refused, RefusalReason::kMethodNotAllowed);
  EXPECT_EQ(wrong.allow, "POST, GET");
  EXPECT_EQ(router.Find(beast_http::verb::get, "/v1/detect/").refused, RefusalReason::kNotFound);
  EXPECT_EQ(TargetPath("/a/b?c=d?e"), "/a/b");
}

TEST(QueryStringTest, DecodesAndKeepsFirstValues) {
  const auto query = ParseQuery("/p?frame_id=cam%200+x&a=1&a=2&flag&bad=%zz%4&&=v");
  EXPECT_EQ(query.at("frame_id"), "cam 0 x");
  EXPECT_EQ(query.at("a"), "1");
  EXPECT_EQ(query.at("flag"), "");
  EXPECT_EQ(query.at("bad"), "%zz%4");
  EXPECT_EQ(query.at(""), "v");
  EXPECT_TRUE(ParseQuery("/p").empty());
}

TEST(RestOptionsTest, RangesAreCheckedAndNamed) {
  InferenceRequest request;
  std::string frame = "default";
  ASSERT_TRUE(ParseDetectQuery({{"max_proposals", "7"},
                                {"obstacle_threshold", "0.25"},
                                {"map", "none"},
                                {"timeout_ms", "3600000"},
                                {"frame_id", "f"}},
                               &request, &frame)
                  .ok());
  EXPECT_EQ(request.options.max_proposals, 7);
  EXPECT_FLOAT_EQ(request.options.obstacle_threshold, 0.25f);
  EXPECT_FALSE(request.encode_map_png);
  EXPECT_TRUE(request.deadline.has_value());
  EXPECT_EQ(frame, "f");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"timeout_ms", "9223372036854775807"},
      {"timeout_ms", "3600001"},
      {"timeout_ms", "1.5"},
      {"max_proposals", "10001"},
      {"max_proposals", ""},
      {"obstacle_threshold", "-0.01"},
      {"obstacle_threshold", "inf"},
      {"obstacle_threshold", "0.5x"},
  };
  for (const auto& [name, value] : bad) {
    InferenceRequest refused;
    const Status status = ParseDetectQuery({{name, value}}, &refused, &frame);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << name << "=" << value;
    EXPECT_NE(status.message().find(name), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace tod::server::http
