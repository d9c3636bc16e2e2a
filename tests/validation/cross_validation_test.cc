#include "core/validation/cross_validation.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tod {
namespace {

std::vector<std::string> Stems(std::vector<int> numbers) {
  std::vector<std::string> out;
  for (int n : numbers) out.push_back(std::to_string(n));
  return out;
}

TEST(ConsecutiveFoldsTest, RunsOfFrameNumbersNeverInterleaved) {
  // Listed out of order and with names that sort differently as text (10 < 9).
  auto folds = ConsecutiveFolds(Stems({10, 3, 0, 9, 1, 2, 4, 8, 5, 7, 6}), 3);
  ASSERT_TRUE(folds.ok()) << folds.status().message();
  ASSERT_EQ(folds->size(), 3u);
  EXPECT_EQ((*folds)[0].stems, Stems({0, 1, 2}));
  // 11 frames into 3: sizes 3, 4, 4, in order, every frame once.
  std::vector<std::string> joined;
  for (const CvFold& f : *folds) joined.insert(joined.end(), f.stems.begin(), f.stems.end());
  EXPECT_EQ(joined, Stems({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ((*folds)[1].stems, Stems({3, 4, 5, 6}));
  EXPECT_EQ((*folds)[2].stems, Stems({7, 8, 9, 10}));
}

TEST(ConsecutiveFoldsTest, NamesThatAreNotNumbersComeAfterInNameOrder) {
  auto folds = ConsecutiveFolds({"b", "12", "a", "2"}, 2);
  ASSERT_TRUE(folds.ok());
  EXPECT_EQ((*folds)[0].stems, (std::vector<std::string>{"2", "12"}));
  EXPECT_EQ((*folds)[1].stems, (std::vector<std::string>{"a", "b"}));
}

TEST(ConsecutiveFoldsTest, RefusesTooFewFramesOrFolds) {
  EXPECT_FALSE(ConsecutiveFolds(Stems({0, 1}), 3).ok());
  EXPECT_FALSE(ConsecutiveFolds(Stems({0, 1, 2}), 1).ok());
}

TEST(FlattenMetricsTest, NumbersByPathWithoutTextFlagsOrNulls) {
  const nlohmann::json eval = {
      {"frames", 20},
      {"free_space", "road label"},
      {"map_superpixel_shares", true},
      {"regression", {{"BP+Fusion@4", {{"ap", 0.25}, {"fpr_at_tpr95", nullptr}}}}}};
  const std::map<std::string, double> flat = FlattenMetrics(eval);
  EXPECT_EQ(flat.size(), 2u);
  EXPECT_DOUBLE_EQ(flat.at("frames"), 20);
  EXPECT_DOUBLE_EQ(flat.at("regression/BP+Fusion@4/ap"), 0.25);
}

nlohmann::json EvalOf(double ap, double tpr) {
  return {{"regression", {{"BP+Fusion@4", {{"ap", ap}, {"tpr_at_fpr", {{"0.020", tpr}}}}}}}};
}

TEST(CrossValidationToJsonTest, SeedsAveragedPerFoldThenMeanAndSpreadOverFolds) {
  CrossValidationReport report;
  report.seeds = 2;
  report.first_seed = 7;
  report.folds = {{Stems({0, 1})}, {Stems({2, 3})}, {Stems({4, 5})}};
  report.runs = {{EvalOf(0.2, 0.8), EvalOf(0.4, 0.6)},
                 {EvalOf(0.5, 0.9), EvalOf(0.5, 0.9)},
                 {EvalOf(0.0, 0.3), EvalOf(0.2, 0.5)}};
  const nlohmann::json cv = CrossValidationToJson(report);
  EXPECT_EQ(cv["folds"], 3);
  EXPECT_EQ(cv["seeds"], 2);
  EXPECT_EQ(cv["first_seed"], 7);
  EXPECT_EQ(cv["fold_frames"][1], nlohmann::json({"2", "3", 2}));
  const std::string ap = "regression/BP+Fusion@4/ap";
  EXPECT_DOUBLE_EQ(cv["per_fold"][0][ap].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(cv["per_fold"][2][ap].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(cv["mean"][ap].get<double>(), (0.3 + 0.5 + 0.1) / 3);
  EXPECT_DOUBLE_EQ(cv["min"][ap].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(cv["max"][ap].get<double>(), 0.5);
  const std::string tpr = "regression/BP+Fusion@4/tpr_at_fpr/0.020";
  EXPECT_DOUBLE_EQ(cv["min"][tpr].get<double>(), 0.4);
  EXPECT_EQ(cv["runs"][1].size(), 2u);

  const std::string table = FormatCrossValidation(report);
  EXPECT_NE(table.find("3-fold cross-validation, 2 seeds from 7"), std::string::npos) << table;
  EXPECT_NE(table.find("BP+Fusion pixel AP"), std::string::npos) << table;
  EXPECT_NE(table.find("0.100-0.500"), std::string::npos) << table;
}

TEST(CrossValidationToJsonTest, AMetricUndefinedInOneFoldIsSummedOverTheOthers) {
  CrossValidationReport report;
  report.folds = {{Stems({0})}, {Stems({1})}};
  report.runs = {{EvalOf(0.2, 0.5)}, {{{"regression", {{"BP+Fusion@4", {{"ap", nullptr}}}}}}}};
  const nlohmann::json cv = CrossValidationToJson(report);
  EXPECT_DOUBLE_EQ(cv["mean"]["regression/BP+Fusion@4/ap"].get<double>(), 0.2);
}

}  // namespace
}  // namespace tod
