// ComputeOcclusionEdges: the maps of every stage, and a stage that rejects its input is an error
// that names it (not an empty map handed on to the next stage).
#include "core/pipeline/frame_stages.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/proposal_features.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

TEST(FrameStagesTest, ComputesEveryMapOnR1) {
  const RoadFrameMaps maps;
  const Result<OcclusionEdges>& oaocc = maps.oaocc;
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
  const RoadFrameMaps maps;
  const auto& [bundle, frame, geometry, oaocc] = maps;
  ASSERT_GE(geometry.regions.num_layers(), 2);
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

// The detector builds R1's colour tables beside the regions' merge and hands them to the
// features; the rows must be those of tables built by the feature computer itself.
TEST(FrameStagesTest, ColourTablesBuiltBeforehandGiveTheSameFeatures) {
  const RoadFrameMaps maps;
  const auto& [bundle, frame, geometry, oaocc] = maps;
  ASSERT_TRUE(oaocc.ok()) << oaocc.status().ToString();
  const ProposalSet proposals = ProposeBoxes(
      *oaocc, geometry.regions, bundle.params.boxes,
      DetectorProposalOptions(bundle.params, geometry.regions.num_layers()), geometry.size_filter);
  ASSERT_GT(proposals.boxes.size(), 0u);
  BoxFeatureOptions options = FeatureOptionsForFrame(bundle, frame.cols, frame.rows);
  options.vertical_edges = true;  // both tables
  const auto rows_with = [&](FrameColourTables colour) {
    cv::Mat1f rows(static_cast<int>(proposals.boxes.size()), NumBoxFeatures(options), 0.f);
    ProposalFeatureComputer(frame, *oaocc, geometry.regions, proposals, options, 1,
                            std::move(colour))
        .ComputeRange(0, proposals.boxes.size(), rows);
    return rows;
  };
  const cv::Mat1f inside = rows_with({});
  const FrameColourTables beforehand = BuildFrameColourTables(frame, oaocc->r1, options);
  ASSERT_NE(beforehand.colour, nullptr);
  ASSERT_NE(beforehand.vertical, nullptr);
  const cv::Mat1f handed = rows_with(beforehand);
  ASSERT_EQ(handed.size(), inside.size());
  EXPECT_EQ(cv::norm(handed, inside, cv::NORM_INF), 0.0);
  // The handed tables are the ones read: tables of another image give other rows.
  const cv::Mat3b inverted = cv::Scalar::all(255) - frame;
  const cv::Mat1f other = rows_with(BuildFrameColourTables(inverted, oaocc->r1, options));
  EXPECT_GT(cv::norm(other, inside, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace tod
