#include "core/forest/random_forest.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "core/forest/tree_builder.h"
#include "tests/forest/fitted_forest.h"

namespace tod {
namespace {

struct Data {
  cv::Mat1f x;
  std::vector<float> y;
};

// Uniform features in [0, 1); the target is computed from them by `f`.
template <typename Fn>
Data MakeData(int rows, int cols, unsigned seed, Fn f) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  Data d{cv::Mat1f(rows, cols), std::vector<float>(rows)};
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) d.x(r, c) = uniform(gen);
    d.y[r] = f(d.x[r]);
  }
  return d;
}

double Mse(const RandomForest& forest, const Data& d) {
  double sum = 0.0;
  for (int r = 0; r < d.x.rows; ++r) {
    const double e = forest.Predict(d.x[r]) - d.y[r];
    sum += e * e;
  }
  return sum / d.x.rows;
}

ForestParams SmallParams() {
  ForestParams p;
  p.num_trees = 40;
  p.max_features = 2;
  p.min_leaf_size = 3;
  p.threads = 2;
  return p;
}

TEST(RandomForest, FitsLinearFunction) {
  auto f = [](const float* x) { return x[0] + 2.f * x[1]; };
  const Data train = MakeData(2000, 4, 1, f);
  const Data test = MakeData(500, 4, 2, f);
  const RandomForest forest = FittedForest(train.x, train.y, SmallParams());
  ASSERT_EQ(forest.num_trees(), 40);
  ASSERT_EQ(forest.num_features(), 4);
  // Var(y) = 1/12 + 4/12 ~ 0.417; a forest on 2000 points gets well under 5 % of that.
  EXPECT_LT(Mse(forest, test), 0.02);
}

TEST(RandomForest, FitsStepFunction) {
  auto f = [](const float* x) { return x[2] > 0.3f ? 5.f : -1.f; };
  const Data train = MakeData(1000, 3, 3, f);
  const Data test = MakeData(300, 3, 4, f);
  const RandomForest forest = FittedForest(train.x, train.y, SmallParams());
  EXPECT_LT(Mse(forest, test), 0.1);  // Var(y) = 36 * 0.21 ~ 7.6
}

TEST(RandomForest, ClassificationByRegressionOnSeparableData) {
  // Class 1 iff x0 > 0.5, with a margin: no training point in (0.4, 0.6).
  auto label = [](const float* x) { return x[0] > 0.5f ? 1.f : 0.f; };
  Data train = MakeData(600, 3, 5, label);
  for (int r = 0; r < train.x.rows; ++r) {
    train.x(r, 0) = train.y[r] > 0.5f ? 0.6f + 0.4f * train.x(r, 0) : 0.8f * train.x(r, 0);
  }
  ForestParams p = SmallParams();
  p.max_features = 3;
  const RandomForest forest = FittedForest(train.x, train.y, p);
  const float negative[3] = {0.2f, 0.5f, 0.5f};
  const float positive[3] = {0.8f, 0.5f, 0.5f};
  EXPECT_LT(forest.Predict(negative), 0.05f);
  EXPECT_GT(forest.Predict(positive), 0.95f);
  for (int r = 0; r < train.x.rows; ++r) {
    EXPECT_NEAR(forest.Predict(train.x[r]), train.y[r], 0.2) << "row " << r;
  }
}

TEST(RandomForest, SameSeedSamePredictionsRegardlessOfThreads) {
  auto f = [](const float* x) { return std::sin(6.f * x[0]) + x[1] * x[2]; };
  const Data train = MakeData(500, 5, 6, f);
  const Data test = MakeData(100, 5, 7, f);
  ForestParams p = SmallParams();
  p.num_trees = 9;
  p.threads = 1;
  const RandomForest one = FittedForest(train.x, train.y, p);
  p.threads = 2;
  const RandomForest two = FittedForest(train.x, train.y, p);
  p.threads = 4;
  const RandomForest four = FittedForest(train.x, train.y, p);
  p.seed = 2;
  const RandomForest other_seed = FittedForest(train.x, train.y, p);
  int differing = 0;
  for (int r = 0; r < test.x.rows; ++r) {
    const float expected = one.Predict(test.x[r]);
    EXPECT_EQ(two.Predict(test.x[r]), expected);
    EXPECT_EQ(four.Predict(test.x[r]), expected);
    if (other_seed.Predict(test.x[r]) != expected) ++differing;
  }
  EXPECT_EQ(one.num_nodes(), two.num_nodes());
  EXPECT_GT(differing, 50);  // the seed matters
}

TEST(RandomForest, FewerSamplesThanMinLeafGivesConstant) {
  cv::Mat1f x = (cv::Mat1f(4, 2) << 0, 0, 1, 1, 2, 0, 3, 1);
  const std::vector<float> y = {1, 2, 3, 4};
  ForestParams p = SmallParams();
  p.min_leaf_size = 5;
  const RandomForest forest = FittedForest(x, y, p);
  ASSERT_FALSE(forest.empty());
  EXPECT_EQ(forest.num_nodes(), forest.num_trees());  // every tree is a single leaf
  const float prediction = forest.Predict(x[0]);
  for (int r = 1; r < 4; ++r) EXPECT_EQ(forest.Predict(x[r]), prediction);
  const float far[2] = {-100.f, 100.f};
  EXPECT_EQ(forest.Predict(far), prediction);
  EXPECT_GE(prediction, 1.f);  // a mean of bootstrap means of {1, 2, 3, 4}
  EXPECT_LE(prediction, 4.f);
}

TEST(RandomForest, LeavesRespectMinLeafSizeAndDepth) {
  const Data train = MakeData(200, 3, 8, [](const float* x) { return x[0] * 10.f + x[1]; });
  ForestParams p = SmallParams();
  p.num_trees = 5;
  p.min_leaf_size = 20;
  const RandomForest forest = FittedForest(train.x, train.y, p);
  for (int t = 0; t < forest.num_trees(); ++t) {
    // 200 bootstrap samples, each leaf >= 20 of them: at most 10 leaves; a deep tree uses most.
    EXPECT_LE(forest.CountLeaves(t), 10);
    EXPECT_GE(forest.CountLeaves(t), 5);
  }
  p.min_leaf_size = 1;
  p.max_depth = 2;
  const RandomForest shallow = FittedForest(train.x, train.y, p);
  for (int t = 0; t < shallow.num_trees(); ++t) EXPECT_EQ(shallow.CountLeaves(t), 4);
  EXPECT_EQ(shallow.CountLeaves(-1), 0);
  EXPECT_EQ(shallow.CountLeaves(5), 0);
}

TEST(RandomForest, SingleFeatureThresholdIsMidway) {
  // x in {1, 4}: every tree that sees both values splits at 2.5 and goes left when x <= 2.5.
  cv::Mat1f x(20, 1);
  std::vector<float> y(20);
  for (int r = 0; r < 20; ++r) {
    x(r, 0) = r < 10 ? 1.f : 4.f;
    y[r] = r < 10 ? 0.f : 1.f;
  }
  ForestParams p = SmallParams();
  p.min_leaf_size = 1;
  const RandomForest forest = FittedForest(x, y, p);
  const float at[4] = {2.49f, 2.5f, 2.51f, 1000.f};
  EXPECT_EQ(forest.Predict(&at[0]), 0.f);
  EXPECT_EQ(forest.Predict(&at[1]), 0.f);
  EXPECT_EQ(forest.Predict(&at[2]), 1.f);
  EXPECT_EQ(forest.Predict(&at[3]), 1.f);
}

TEST(RandomForest, MidpointThresholdSeparatesAdjacentFloats) {
  EXPECT_EQ(MidpointThreshold(1.f, 2.f), 1.5f);
  EXPECT_EQ(MidpointThreshold(-3.f, 1.f), -1.f);
  const float next = std::nextafter(1.f, 2.f);
  const float t = MidpointThreshold(1.f, next);
  EXPECT_TRUE(1.f <= t && t < next) << t;
}

TEST(RandomForest, BatchMatchesSinglePrediction) {
  const Data train = MakeData(300, 3, 9, [](const float* x) { return x[0] - x[2]; });
  const Data test = MakeData(700, 3, 10, [](const float*) { return 0.f; });  // > one block
  ForestParams p = SmallParams();
  p.num_trees = 7;
  const RandomForest forest = FittedForest(train.x, train.y, p);
  const std::vector<float> batch = forest.PredictBatch(test.x);
  ASSERT_EQ(batch.size(), 700u);
  for (int r = 0; r < test.x.rows; ++r) EXPECT_EQ(batch[r], forest.Predict(test.x[r]));
  EXPECT_TRUE(forest.PredictBatch(cv::Mat1f(3, 2, 0.f)).empty());  // wrong column count
  const RandomForest untrained;
  EXPECT_EQ(untrained.PredictBatch(test.x), std::vector<float>(700, 0.f));
  EXPECT_EQ(untrained.Predict(test.x[0]), 0.f);
}

TEST(RandomForest, DefaultMtryIsAThirdOfTheFeatures) {
  // max_features <= 0 resolves to floor(6 / 3) = 2: the forest equals one trained with mtry 2.
  auto f = [](const float* x) { return x[0] > 0.5f ? 1.f : 0.f; };
  const Data train = MakeData(400, 6, 11, f);
  const Data test = MakeData(200, 6, 12, f);
  ForestParams p = SmallParams();
  p.max_features = 0;  // floor(6 / 3) = 2
  const RandomForest default_mtry = FittedForest(train.x, train.y, p);
  p.max_features = 2;
  const RandomForest two = FittedForest(train.x, train.y, p);
  p.max_features = 3;
  const RandomForest three = FittedForest(train.x, train.y, p);
  int differs_from_three = 0;
  for (int r = 0; r < test.x.rows; ++r) {
    EXPECT_EQ(default_mtry.Predict(test.x[r]), two.Predict(test.x[r]));
    if (default_mtry.Predict(test.x[r]) != three.Predict(test.x[r])) ++differs_from_three;
  }
  EXPECT_GT(differs_from_three, 0);  // mtry does change the forest
}

TEST(RandomForest, FitRejectsBadInput) {
  const Data d = MakeData(10, 2, 13, [](const float* x) { return x[0]; });
  const ForestParams p = SmallParams();

  Result<RandomForest> r = RandomForest::Fit(cv::Mat1f(), {}, p);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("features"), std::string::npos);

  r = RandomForest::Fit(d.x, std::vector<float>(9, 0.f), p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("targets has 9"), std::string::npos);

  cv::Mat1f with_nan = d.x.clone();
  with_nan(3, 1) = std::nanf("");
  r = RandomForest::Fit(with_nan, d.y, p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("features(3, 1)"), std::string::npos);

  std::vector<float> bad_targets = d.y;
  bad_targets[7] = INFINITY;
  r = RandomForest::Fit(d.x, bad_targets, p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("targets[7]"), std::string::npos);

  ForestParams bad = p;
  bad.num_trees = 0;
  r = RandomForest::Fit(d.x, d.y, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("num_trees"), std::string::npos);
  bad = p;
  bad.min_leaf_size = 0;
  EXPECT_FALSE(RandomForest::Fit(d.x, d.y, bad).ok());
  bad = p;
  bad.sample_fraction = 0.0;
  EXPECT_FALSE(RandomForest::Fit(d.x, d.y, bad).ok());
  bad = p;
  bad.max_depth = -1;
  EXPECT_FALSE(RandomForest::Fit(d.x, d.y, bad).ok());

  EXPECT_FALSE(RandomForest::Fit(with_nan, d.y, p).ok());
  EXPECT_TRUE(RandomForest::Fit(d.x, d.y, p).ok());
}

TEST(RandomForest, SampleFractionControlsBootstrapSize) {
  // One tree, min leaf 10: 0.1 of 200 rows = 20 draws -> at most 2 leaves.
  const Data d = MakeData(200, 2, 14, [](const float* x) { return x[0]; });
  ForestParams p = SmallParams();
  p.num_trees = 3;
  p.min_leaf_size = 10;
  p.sample_fraction = 0.1;
  const RandomForest forest = FittedForest(d.x, d.y, p);
  for (int t = 0; t < forest.num_trees(); ++t) EXPECT_LE(forest.CountLeaves(t), 2);
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

// Joined forests (one per bag of samples) predict the mean of the parts' predictions, keep every
// tree, survive a save and load, and refuse parts that disagree on the features.
TEST(RandomForest, JoinedForestsPredictTheMeanOfTheParts) {
  auto f = [](const float* x) { return x[0] - x[2]; };
  const Data a = MakeData(600, 3, 11, f);
  const Data b = MakeData(600, 3, 12, f);
  ForestParams params = SmallParams();
  params.num_trees = 10;
  const RandomForest first = FittedForest(a.x, a.y, params);
  params.seed = 2;
  const RandomForest second = FittedForest(b.x, b.y, params);
  auto joined = RandomForest::Join({first, second});
  ASSERT_TRUE(joined.ok()) << joined.status().message();
  EXPECT_EQ(joined->num_trees(), 20);
  EXPECT_EQ(joined->num_nodes(), first.num_nodes() + second.num_nodes());
  const Data test = MakeData(200, 3, 13, f);
  const std::vector<float> batch = joined->PredictBatch(test.x);
  ASSERT_EQ(batch.size(), 200u);
  for (int r = 0; r < test.x.rows; ++r) {
    const float mean = 0.5f * (first.Predict(test.x[r]) + second.Predict(test.x[r]));
    EXPECT_NEAR(joined->Predict(test.x[r]), mean, 1e-5f) << "row " << r;
    EXPECT_EQ(batch[r], joined->Predict(test.x[r]));
  }

  const Result<std::string> bytes = EncodeModel(*joined);
  ASSERT_TRUE(bytes.ok());
  auto loaded = DecodeModel<RandomForest>(*bytes, "joined.bin");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->PredictBatch(test.x), batch);

  const Data wide = MakeData(100, 4, 14, f);
  const RandomForest other = FittedForest(wide.x, wide.y, params);
  auto mismatch = RandomForest::Join({first, other});
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.status().message().find("features"), std::string::npos);
}

}  // namespace
}  // namespace tod
