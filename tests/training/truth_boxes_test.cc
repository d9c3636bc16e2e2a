// TruthBoxes: an obstacle's own box scored as the window scan scores the same window, once per
// region that holds it whole.
#include "core/training/truth_boxes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/pipeline/frame_geometry.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

ObstacleInstance InstanceAt(const Box& box) {
  ObstacleInstance obstacle;
  obstacle.box = box;
  obstacle.mask = cv::Mat1b(box.h, box.w, 1);
  return obstacle;
}

// The scan's own best boxes of every region, given as obstacles, come back with the scan's scores
// in their region, and in every other region that holds them whole.
TEST(TruthBoxesTest, ABoxTheScanFoundKeepsTheScansScoreInItsRegion) {
  const RoadFrameMaps maps;
  const MultilayerRegions& regions = maps.geometry.regions;
  ASSERT_TRUE(maps.oaocc.ok()) << maps.oaocc.status().ToString();
  const EdgeBoxParams& params = maps.bundle.params.boxes;
  std::vector<ObstacleInstance> obstacles;
  std::vector<ScoredBox> found;
  std::vector<int> found_in;
  for (int k = 0; k < regions.num_layers(); ++k) {
    const RegionProposals scanned =
        ProposeRegionBoxes(*maps.oaocc, regions, params, k, /*multistride=*/true, nullptr);
    for (size_t i = 0; i < scanned.boxes.size() && i < 3; ++i) {
      obstacles.push_back(InstanceAt(scanned.boxes[i].box));
      found.push_back(scanned.boxes[i]);
      found_in.push_back(k);
    }
  }
  ASSERT_GE(found.size(), 4u);
  const ProposalSet truth = TruthBoxes(obstacles, *maps.oaocc, regions, params, true);
  ASSERT_EQ(truth.boxes.size(), truth.layer.size());
  for (size_t o = 0; o < found.size(); ++o) {
    int in_own_region = 0;
    for (size_t t = 0; t < truth.boxes.size(); ++t) {
      if (truth.boxes[t].box != found[o].box) continue;
      const Box region = Intersect(regions.layers[truth.layer[t]], maps.oaocc->r1);
      EXPECT_EQ(Intersect(found[o].box, region).area(), found[o].box.area()) << o;
      if (truth.layer[t] == found_in[o]) {
        ++in_own_region;
        EXPECT_NEAR(truth.boxes[t].score, found[o].score, 1e-5f) << o;
      }
    }
    EXPECT_EQ(in_own_region, 1) << o;
  }
}

// A box that no region holds whole (one reaching into the sky above R1) is left out; an empty
// box too.
TEST(TruthBoxesTest, BoxesNoRegionHoldsWholeAreLeftOut) {
  const RoadFrameMaps maps;
  ASSERT_TRUE(maps.oaocc.ok()) << maps.oaocc.status().ToString();
  const Box r1 = maps.oaocc->r1;
  ASSERT_GT(r1.y, 0);
  const std::vector<ObstacleInstance> obstacles = {InstanceAt(Box{r1.x + 10, r1.y - 1, 12, 12}),
                                                   InstanceAt(Box{r1.x + 10, r1.y + 10, 0, 0})};
  const ProposalSet truth =
      TruthBoxes(obstacles, *maps.oaocc, maps.geometry.regions, maps.bundle.params.boxes, true);
  EXPECT_TRUE(truth.boxes.empty());
  EXPECT_TRUE(truth.layer.empty());
}

}  // namespace
}  // namespace tod
