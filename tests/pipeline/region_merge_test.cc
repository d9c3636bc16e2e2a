#include <gtest/gtest.h>

#include <random>

#include "core/pipeline/frame_stages.h"
#include "core/proposals/greedy_nms.h"

namespace tod {
namespace {

// R2 re-scores the same map as R1: a box it finds again must not take a second rank.
TEST(RegionMergeTest, NearCopiesFromInnerRegionsAreSuppressedDistinctBoxesKept) {
  const std::vector<std::vector<ScoredBox>> per_region = {
      {{{100, 100, 40, 40}, 0.9f}, {{300, 100, 40, 40}, 0.5f}},
      {{{101, 100, 40, 40}, 0.95f}, {{500, 120, 12, 12}, 0.7f}},
  };
  const ProposalSet merged = MergeRegionBoxes(per_region, 0.75f, 0.75f);
  ASSERT_EQ(merged.boxes.size(), 3u);
  EXPECT_EQ(merged.boxes[0].box, (Box{101, 100, 40, 40}));  // best of the two copies
  EXPECT_EQ(merged.layer[0], 1);
  EXPECT_EQ(merged.boxes[1].box, (Box{500, 120, 12, 12}));
  EXPECT_EQ(merged.layer[1], 1);
  EXPECT_EQ(merged.boxes[2].box, (Box{300, 100, 40, 40}));
  EXPECT_EQ(merged.layer[2], 0);

  const ProposalSet plain_union = MergeRegionBoxes(per_region, 1.f, 0.75f);  // the authors' merge
  EXPECT_EQ(plain_union.boxes.size(), 4u);
}

// Each region's list has been through its own NMS at the same IoU, so the merge only checks a box
// against the other regions' kept boxes; the reference checks every kept box. Thousands of boxes
// crowded into overlapping regions (many near-copies across regions, many ties of score): the
// same boxes, order and regions. With region lists that have NOT been through such an NMS the
// shortcut would keep near-copies of one region, which the reference suppresses; the shortcut is
// only taken when the caller's region NMS allows it.
TEST(RegionMergeTest, CheckingOnlyOtherRegionsGivesTheMergeOfTheReference) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> pos(0, 300), size(8, 60), score(0, 40);
  std::vector<std::vector<ScoredBox>> raw(4), per_region(4);
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < 3000; ++i) {
      const int w = size(rng);
      raw[k].push_back({{pos(rng) + 20 * k, pos(rng) / 2 + 10 * k, w, w / 2 + size(rng) / 4},
                        static_cast<float>(score(rng)) / 40.f});
    }
    per_region[k] = NonMaximumSuppression(raw[k], 0.75f, 2000);
  }
  const ProposalSet fast = MergeRegionBoxes(per_region, 0.75f, 0.75f);
  const ProposalSet reference = MergeRegionBoxes(per_region, 0.75f, 1.f);
  ASSERT_EQ(fast.boxes.size(), reference.boxes.size());
  EXPECT_LT(fast.boxes.size(), 4u * per_region[0].size());  // regions did suppress each other
  for (std::size_t i = 0; i < fast.boxes.size(); ++i) {
    EXPECT_EQ(fast.boxes[i].box, reference.boxes[i].box) << i;
    EXPECT_EQ(fast.boxes[i].score, reference.boxes[i].score) << i;
    EXPECT_EQ(fast.layer[i], reference.layer[i]) << i;
  }
  // Lists without their own NMS: the reference suppresses within a region too.
  const ProposalSet raw_reference = MergeRegionBoxes(raw, 0.75f, 1.f);
  std::size_t raw_total = 0;
  for (const auto& r : raw) raw_total += r.size();
  EXPECT_LT(raw_reference.boxes.size(), raw_total);
}

}  // namespace
}  // namespace tod
