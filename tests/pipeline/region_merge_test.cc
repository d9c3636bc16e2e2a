#include <gtest/gtest.h>

#include "core/pipeline/frame_stages.h"

namespace tod {
namespace {

// R2 re-scores the same map as R1: a box it finds again must not take a second rank.
TEST(RegionMergeTest, NearCopiesFromInnerRegionsAreSuppressedDistinctBoxesKept) {
  const std::vector<RegionProposals> per_region = {
      {{{{100, 100, 40, 40}, 0.9f}, {{300, 100, 40, 40}, 0.5f}}, 1.f},
      {{{{101, 100, 40, 40}, 0.95f}, {{500, 120, 12, 12}, 0.7f}}, 1.f},
  };
  const ProposalSet merged = MergeRegionBoxes(per_region, 0.75f);
  ASSERT_EQ(merged.boxes.size(), 3u);
  EXPECT_EQ(merged.boxes[0].box, (Box{101, 100, 40, 40}));  // best of the two copies
  EXPECT_EQ(merged.layer[0], 1);
  EXPECT_EQ(merged.boxes[1].box, (Box{500, 120, 12, 12}));
  EXPECT_EQ(merged.layer[1], 1);
  EXPECT_EQ(merged.boxes[2].box, (Box{300, 100, 40, 40}));
  EXPECT_EQ(merged.layer[2], 0);

  const ProposalSet plain_union = MergeRegionBoxes(per_region, 1.f);  // the authors' merge
  EXPECT_EQ(plain_union.boxes.size(), 4u);
}

// Each region's scores are in units of its own map's maximum: an inner region whose map peaks at
// half of R1's scores a window about twice as high as R1 would. The merge keeps the boxes, their
// order and their scores; the common-scale ranking puts R1's box first.
TEST(RegionMergeTest, RanksTheUnionOnOneScaleAndKeepsEachRegionsScores) {
  const std::vector<RegionProposals> per_region = {
      {{{{100, 100, 40, 40}, 0.6f}, {{300, 100, 40, 40}, 0.3f}}, 2.f},
      // On R1's scale: 0.45 and 0.2.
      {{{{600, 120, 20, 20}, 0.9f}, {{700, 120, 12, 12}, 0.4f}}, 1.f},
  };
  const ProposalSet merged = MergeRegionBoxes(per_region, 0.75f);
  ASSERT_EQ(merged.boxes.size(), 4u);
  EXPECT_EQ(merged.layer, (std::vector<int>{1, 0, 1, 0}));  // by the regions' own scores
  EXPECT_EQ(merged.boxes[0].score, 0.9f);
  EXPECT_EQ(merged.layer_scale, (std::vector<float>{1.f, 0.5f}));
  EXPECT_EQ(RankedOnCommonScale(merged),
            (std::vector<Box>{
                {100, 100, 40, 40}, {600, 120, 20, 20}, {300, 100, 40, 40}, {700, 120, 12, 12}}));
}

// A frame without edges has every edge_max 0: the scores rank as they are.
TEST(RegionMergeTest, RegionsWithoutEdgesRankByTheirScores) {
  const std::vector<RegionProposals> per_region = {{{{{10, 10, 20, 20}, 0.2f}}, 0.f},
                                                   {{{{200, 10, 20, 20}, 0.5f}}, 0.f}};
  const ProposalSet merged = MergeRegionBoxes(per_region, 0.75f);
  EXPECT_EQ(merged.layer_scale, (std::vector<float>{1.f, 1.f}));
  EXPECT_EQ(RankedOnCommonScale(merged), (std::vector<Box>{{200, 10, 20, 20}, {10, 10, 20, 20}}));
}

}  // namespace
}  // namespace tod
