#include <gtest/gtest.h>

#include "core/pipeline/frame_stages.h"

namespace tod {
namespace {

// R2 re-scores the same map as R1: a box it finds again must not take a second rank.
TEST(RegionMergeTest, NearCopiesFromInnerRegionsAreSuppressedDistinctBoxesKept) {
  const std::vector<std::vector<ScoredBox>> per_region = {
      {{{100, 100, 40, 40}, 0.9f}, {{300, 100, 40, 40}, 0.5f}},
      {{{101, 100, 40, 40}, 0.95f}, {{500, 120, 12, 12}, 0.7f}},
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

}  // namespace
}  // namespace tod
