// One bound for max_proposals on both front ends: the REST query parser and the engine's
// admission check (which gRPC requests meet) both take it from kMaxRequestProposals, and each
// keeps its own message.
#include <gtest/gtest.h>

#include <future>
#include <string>

#include "server/core/inference_engine.h"
#include "server/rest_options.h"
#include "tests/service/fake_detectors.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

TEST(MaxProposalsTest, IsTheDocumentedBound) { EXPECT_EQ(kMaxRequestProposals, 10000); }

TEST(MaxProposalsTest, RestAcceptsTheBoundAndRefusesOneMore) {
  InferenceRequest request;
  std::string frame;
  ASSERT_TRUE(ParseDetectQuery({{"max_proposals", "10000"}}, &request, &frame).ok());
  EXPECT_EQ(request.options.max_proposals, kMaxRequestProposals);
  const Status refused = ParseDetectQuery({{"max_proposals", "10001"}}, &request, &frame);
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(refused.message(),
            "query parameter max_proposals='10001' is not a valid number in 0..10000");
}

// What the engine answers at admission for `max_proposals`.
InferenceResult Admit(int max_proposals) {
  ModelHolder models;
  models.Install(std::make_shared<testing::GatedDetector>("v1"), "/models/one");
  InferenceEngine engine(EngineConfig{}, models, nullptr);
  engine.Start();
  const std::string image = testing::RoadPng();
  InferenceRequest request;
  request.image = image;
  request.options.max_proposals = max_proposals;
  request.encode_map_png = false;
  std::promise<InferenceResult> promise;
  engine.Submit(request, [&](InferenceResult result) { promise.set_value(std::move(result)); });
  return promise.get_future().get();
}

TEST(MaxProposalsTest, EngineAcceptsTheBoundAndRefusesOneMore) {
  EXPECT_TRUE(Admit(kMaxRequestProposals).status.ok());
  const InferenceResult refused = Admit(kMaxRequestProposals + 1);
  EXPECT_EQ(refused.rejection, Rejection::kBadRequest);
  EXPECT_EQ(refused.status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(refused.status.message(), "max_proposals: 10001 is outside [0, 10000]");
  EXPECT_EQ(Admit(-1).status.message(), "max_proposals: -1 is outside [0, 10000]");
}

}  // namespace
}  // namespace tod::server
