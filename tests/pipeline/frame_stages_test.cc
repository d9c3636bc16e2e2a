// ComputeOcclusionEdges: the maps of every stage, and a stage that rejects its input is an error
// that names it (not an empty map handed on to the next stage).
#include "core/pipeline/frame_stages.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/pipeline/frame_geometry.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

TEST(FrameStagesTest, ComputesEveryMapOnR1) {
  const ModelBundle bundle = TinyBundle();
  const cv::Mat3b frame = RoadFrame(512, 256);
  const FrameGeometry geometry = GeometryForFrame(bundle, frame.cols, frame.rows);
  const Result<OcclusionEdges> oaocc = ComputeOcclusionEdges(
      frame, geometry.regions, *bundle.edges, &bundle.occlusion, bundle.params, true);
  ASSERT_TRUE(oaocc.ok()) << oaocc.status().ToString();
  const cv::Size crop = oaocc->r1.rect().size();
  EXPECT_EQ(oaocc->base_edge.size(), crop);
  EXPECT_EQ(oaocc->superpixels.labels.size(), crop);
  EXPECT_GT(oaocc->superpixels.count, 1);
  EXPECT_EQ(oaocc->occlusion.size(), crop);
  EXPECT_GT(cv::countNonZero(oaocc->occlusion), 0);
}

TEST(FrameStagesTest, SuperpixelStageRejectingItsParametersIsAnError) {
  ModelBundle bundle = TinyBundle();
  bundle.params.superpixels.k = 0;  // a loaded bundle cannot hold this (its params are checked)
  const cv::Mat3b frame = RoadFrame(512, 256);
  const FrameGeometry geometry = GeometryForFrame(bundle, frame.cols, frame.rows);
  const Result<OcclusionEdges> oaocc = ComputeOcclusionEdges(
      frame, geometry.regions, *bundle.edges, &bundle.occlusion, bundle.params, true);
  ASSERT_FALSE(oaocc.ok());
  EXPECT_EQ(oaocc.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(oaocc.status().message().find("sticky superpixels"), std::string::npos)
      << oaocc.status().ToString();
}

// With several threads the regions are scanned side by side (and each scan split over the
// threads): the boxes, their order and their regions are those of one thread.
TEST(FrameStagesTest, RegionsSideBySideGiveTheBoxesOfOneThread) {
  const ModelBundle bundle = TinyBundle();
  const cv::Mat3b frame = RoadFrame(512, 256);
  const FrameGeometry geometry = GeometryForFrame(bundle, frame.cols, frame.rows);
  ASSERT_GE(geometry.regions.num_layers(), 2);
  const Result<OcclusionEdges> oaocc = ComputeOcclusionEdges(
      frame, geometry.regions, *bundle.edges, &bundle.occlusion, bundle.params, true);
  ASSERT_TRUE(oaocc.ok()) << oaocc.status().ToString();
  const auto propose = [&](int threads) {
    ProposalOptions options = DetectorProposalOptions(bundle.params, geometry.regions.num_layers());
    options.threads = threads;
    return ProposeBoxes(*oaocc, geometry.regions, bundle.params.boxes, options,
                        geometry.size_filter);
  };
  const ProposalSet one = propose(1);
  ASSERT_GT(one.boxes.size(), 0u);
  std::vector<bool> region_seen(geometry.regions.num_layers(), false);
  for (const int k : one.layer) region_seen[k] = true;
  EXPECT_GE(std::count(region_seen.begin(), region_seen.end(), true), 2);
  for (const int threads : {2, 4}) {
    const ProposalSet several = propose(threads);
    ASSERT_EQ(several.boxes.size(), one.boxes.size()) << threads;
    for (size_t i = 0; i < one.boxes.size(); ++i) {
      EXPECT_EQ(several.boxes[i].box, one.boxes[i].box) << threads << " " << i;
      EXPECT_EQ(several.boxes[i].score, one.boxes[i].score) << threads << " " << i;
      EXPECT_EQ(several.layer[i], one.layer[i]) << threads << " " << i;
    }
    EXPECT_TRUE(several.truncated_regions.empty());
  }
}

}  // namespace
}  // namespace tod
