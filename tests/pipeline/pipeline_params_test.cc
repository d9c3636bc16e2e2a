#include "core/pipeline/pipeline_params.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

TEST(PipelineParams, DefaultsAreThePapers) {
  const PipelineParams p;
  EXPECT_EQ(p.regions.num_layers, 4);
  EXPECT_FLOAT_EQ(p.boxes.alpha, 0.65f);
  EXPECT_FLOAT_EQ(p.boxes.beta, 0.75f);
  EXPECT_FLOAT_EQ(p.boxes.max_aspect_ratio, 6.f);
  EXPECT_FLOAT_EQ(p.boxes.max_wide_aspect_ratio, 0.f);  // tau_a on both sides
  EXPECT_FLOAT_EQ(p.fusion.beta1, 0.3f);
  EXPECT_FLOAT_EQ(p.probability_map.nms_iou, 0.7f);
  EXPECT_TRUE(p.multistride);
  EXPECT_FLOAT_EQ(p.probability_map.isolation.exponent, 0.f);  // the paper's map
}

TEST(PipelineParams, JsonRoundTripAndMissingKeysKeepDefaults) {
  PipelineParams p;
  p.boxes.min_box_area = 60;
  p.multistride = false;
  auto back = PipelineParamsFromJson(ToJson(p));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_FLOAT_EQ(back->boxes.min_box_area, 60.f);
  EXPECT_FALSE(back->multistride);
  auto partial = PipelineParamsFromJson({{"fusion", {{"beta1", 0.5}}}});
  ASSERT_TRUE(partial.ok());
  EXPECT_FLOAT_EQ(partial->fusion.beta1, 0.5f);
  EXPECT_FLOAT_EQ(partial->fusion.keep_ratio, 0.5f);
  EXPECT_EQ(partial->superpixels.k, 1024);
  // A manifest from before the wide bound keeps the paper's grid; `tod train` writes 10.
  EXPECT_FLOAT_EQ(partial->boxes.max_wide_aspect_ratio, 0.f);
  EXPECT_FLOAT_EQ(TrainingDefaultParams().boxes.max_wide_aspect_ratio, 10.f);
}

// The regressors' row width and its words follow the optional features, each on its own;
// a manifest without the newer key keeps the older bundles' 20 or 21.
TEST(PipelineParams, ProposalFeaturesFollowTheOptionalFeatures) {
  PipelineParams p;
  EXPECT_EQ(ProposalFeatureCount(p), 20);
  EXPECT_EQ(ProposalFeatureSet(p), "the paper's 20");
  p.vertical_edge_feature = true;
  EXPECT_EQ(ProposalFeatureCount(p), 21);
  EXPECT_EQ(ProposalFeatureSet(p), "the paper's 20, the vertical edge share");
  p.road_surround_feature = true;
  EXPECT_EQ(ProposalFeatureCount(p), 22);
  EXPECT_EQ(ProposalFeatureSet(p),
            "the paper's 20, the vertical edge share, the surround unlike the road");
  p.vertical_edge_feature = false;
  EXPECT_EQ(ProposalFeatureCount(p), 21);
  EXPECT_EQ(ProposalFeatureSet(p), "the paper's 20, the surround unlike the road");
  const auto older = PipelineParamsFromJson({{"vertical_edge_feature", true}});
  ASSERT_TRUE(older.ok());
  EXPECT_FALSE(older->road_surround_feature);
  EXPECT_EQ(ProposalFeatureCount(*older), 21);
}

TEST(PipelineParams, WrongTypesAndRangesAreErrors) {
  EXPECT_FALSE(PipelineParamsFromJson({{"boxes", {{"alpha", "big"}}}}).ok());
  EXPECT_FALSE(PipelineParamsFromJson({{"boxes", {{"alpha", 1.5}}}}).ok());
  EXPECT_FALSE(PipelineParamsFromJson({{"fusion", {{"keep_ratio", 2}}}}).ok());
  for (const nlohmann::json& isolation :
       {nlohmann::json{{"exponent", -1}}, nlohmann::json{{"context_boxes", 0}},
        nlohmann::json{{"surround", 0.5}}}) {
    EXPECT_FALSE(PipelineParamsFromJson({{"probability_map", {{"isolation", isolation}}}}).ok())
        << isolation;
  }
  auto fitted = PipelineParamsFromJson({{"probability_map", {{"isolation", {{"exponent", 2}}}}}});
  ASSERT_TRUE(fitted.ok()) << fitted.status().ToString();
  EXPECT_FLOAT_EQ(fitted->probability_map.isolation.exponent, 2.f);
  EXPECT_EQ(fitted->probability_map.isolation.context_boxes, 1000);
}

}  // namespace
}  // namespace tod
