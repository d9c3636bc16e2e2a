// ComputeOcclusionEdges: the maps of every stage, and a stage that rejects its input is an error
// that names it (not an empty map handed on to the next stage).
#include "core/pipeline/frame_stages.h"

#include <gtest/gtest.h>

#include <string>

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

}  // namespace
}  // namespace tod
