#include "core/pipeline/parallel.h"

#include <gtest/gtest.h>

#include <stdexcept>

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

}  // namespace
}  // namespace tod
