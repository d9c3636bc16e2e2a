#include "core/pipeline/parallel.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "core/pipeline/bad_frames.h"

namespace tod {
namespace {

TEST(ParallelForTest, AnExceptionBecomesThatFramesErrorAndTheOthersRun) {
  for (int threads : {1, 2, 4}) {
    std::vector<int> ran(20, 0);
    const std::vector<Status> statuses = ParallelFor(20, threads, [&](int i) -> Status {
      ran[i] = 1;
      if (i == 7) throw std::runtime_error("boom");
      if (i == 11) return Status::DataLoss("bad file");
      return Status::Ok();
    });
    ASSERT_EQ(statuses.size(), 20u);
    for (int i = 0; i < 20; ++i) {
      EXPECT_EQ(ran[i], 1) << i;
      EXPECT_EQ(statuses[i].ok(), i != 7 && i != 11) << i;
    }
    EXPECT_NE(statuses[7].message().find("boom"), std::string::npos);
  }
}

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
