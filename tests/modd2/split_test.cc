// The versioned default split and split files.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/modd2/modd2_split.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

TEST(Modd2Split, SequenceNamesAreTheOfficial28) {
  const std::vector<std::string>& names = Modd2SequenceNames();
  ASSERT_EQ(names.size(), 28u);
  EXPECT_EQ(names.front(), "kope67-00-00004500-00005050");
  EXPECT_EQ(names[9], "kope71-01-00011210-00011320");
  EXPECT_EQ(names.back(), "kope82-00-00012030-00012700");
  // E - S summed over the sequences is the paper's 11,675 frames.
  long long frames = 0;
  for (const std::string& n : names) {
    frames += std::stoll(n.substr(19, 8)) - std::stoll(n.substr(10, 8));
  }
  EXPECT_EQ(frames, 11675);
}

TEST(Modd2Split, DefaultSplitIsTheDocumentedDraw) {
  const Modd2Split& split = DefaultModd2Split();
  const Modd2Split drawn = DrawModd2Split(kModd2DefaultSplitSeed, kModd2TrainFraction);
  EXPECT_EQ(split.train, drawn.train);
  EXPECT_EQ(split.test, drawn.test);
  EXPECT_EQ(split.excluded, drawn.excluded);
  EXPECT_NE(split.source.find(kModd2DefaultSplitVersion), std::string::npos);
}

TEST(Modd2Split, DefaultSplitProperties) {
  const Modd2Split& split = DefaultModd2Split();
  EXPECT_EQ(split.train.size(), 8u);  // round(0.3 * 28)
  EXPECT_EQ(split.test.size() + split.excluded.size(), 20u);
  std::set<std::string> all(split.train.begin(), split.train.end());
  all.insert(split.test.begin(), split.test.end());
  all.insert(split.excluded.begin(), split.excluded.end());
  EXPECT_EQ(all.size(), 28u);  // a partition of the 28 sequences
  const std::vector<std::string>& names = Modd2SequenceNames();
  for (int id : Modd2ReflectionSequenceIds()) {
    const std::string& name = names[id - 1];
    EXPECT_EQ(std::count(split.test.begin(), split.test.end(), name), 0) << name;
  }
  for (const std::string& name : split.excluded) {
    const int id =
        static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin()) + 1;
    const std::vector<int>& reflections = Modd2ReflectionSequenceIds();
    EXPECT_NE(std::find(reflections.begin(), reflections.end(), id), reflections.end()) << name;
  }
}

TEST(Modd2Split, DrawDependsOnTheSeed) {
  const Modd2Split a = DrawModd2Split(1);
  const Modd2Split b = DrawModd2Split(2);
  EXPECT_EQ(a.train.size(), 8u);
  EXPECT_NE(a.train, b.train);
  EXPECT_EQ(DrawModd2Split(1).train, a.train);  // deterministic
  EXPECT_EQ(DrawModd2Split(1, 0.5).train.size(), 14u);
}

TEST(Modd2Split, SelectSequences) {
  Modd2Split split;
  split.train = {"b", "a"};
  split.test = {"c"};
  split.excluded = {"d"};
  EXPECT_EQ(*SelectModd2Sequences(split, "train"), (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(*SelectModd2Sequences(split, "test"), (std::vector<std::string>{"c"}));
  EXPECT_EQ(*SelectModd2Sequences(split, "all"), (std::vector<std::string>{"a", "b", "c", "d"}));
  const Result<std::vector<std::string>> bad = SelectModd2Sequences(split, "val");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("'val'"), std::string::npos);
}

class Modd2SplitFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // One file per test: CTest may run the tests of this binary in parallel.
    path_ =
        (fs::path(::testing::TempDir()) /
         ("modd2_split_" +
          std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".txt"))
            .string();
  }
  void TearDown() override { fs::remove(path_); }
  std::string path_;
};

TEST_F(Modd2SplitFileTest, RoundTrip) {
  const Modd2Split& split = DefaultModd2Split();
  std::ofstream(path_) << FormatModd2SplitFile(split);
  const Result<Modd2Split> read = ReadModd2SplitFile(path_);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->train, split.train);
  EXPECT_EQ(read->test, split.test);
  EXPECT_EQ(read->excluded, split.excluded);
  EXPECT_EQ(read->source, path_);
}

TEST_F(Modd2SplitFileTest, CommentsBlankLinesAndErrors) {
  std::ofstream(path_) << "# header\n\ntrain a  # trailing comment\n  test b\n";
  const Result<Modd2Split> read = ReadModd2SplitFile(path_);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->train, std::vector<std::string>{"a"});
  EXPECT_EQ(read->test, std::vector<std::string>{"b"});

  std::ofstream(path_) << "train a\nvalidation b\n";
  Result<Modd2Split> bad = ReadModd2SplitFile(path_);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(path_ + ":2"), std::string::npos) << bad.status().message();
  std::ofstream(path_) << "train a b\n";
  bad = ReadModd2SplitFile(path_);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(path_ + ":1"), std::string::npos);
  fs::remove(path_);
  EXPECT_EQ(ReadModd2SplitFile(path_).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace tod
