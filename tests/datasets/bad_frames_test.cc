#include "core/datasets/bad_frames.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

TEST(BadFramePolicyTest, FailNamesTheFrameSkipListsIt) {
  const std::vector<Status> statuses = {Status::Ok(), Status::DataLoss("cannot decode"),
                                        Status::Ok()};
  const auto name = [](int i) { return std::string("f").append(std::to_string(i)); };
  std::vector<SkippedFrame> skipped;
  const Status failed = ApplyBadFramePolicy(statuses, name, BadFramePolicy::kFail, &skipped);
  EXPECT_FALSE(failed.ok());
  EXPECT_NE(failed.message().find("frame f1"), std::string::npos);
  EXPECT_TRUE(skipped.empty());
  EXPECT_TRUE(ApplyBadFramePolicy(statuses, name, BadFramePolicy::kSkip, &skipped).ok());
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_EQ(skipped[0].frame, "f1");
  EXPECT_EQ(SkippedFramesToJson(skipped)["count"], 1);
  EXPECT_FALSE(ParseBadFramePolicy("ignore").ok());
}

}  // namespace
}  // namespace tod
