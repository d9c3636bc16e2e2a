// The frame budget (core/pipeline/frame_budget.h) and the cores a request may use: what Detect
// does when the budget runs out, and that threads never change the result.
#include "core/pipeline/frame_budget.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

#include "core/pipeline/obstacle_detector.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

using Clock = std::chrono::steady_clock;

TEST(FrameBudgetTest, NoBudgetHasNoDeadlines) {
  const FrameBudget none;
  EXPECT_FALSE(none.limited());
  EXPECT_EQ(none.ProposalsDeadline(), Clock::time_point::max());
  const FrameBudget zero(Clock::now(), 0);
  EXPECT_FALSE(zero.limited());
  EXPECT_EQ(zero.RegressionDeadline(), Clock::time_point::max());
}

// Each stage gets its share of the time left when it asks, so time the whole stages before it
// took is not charged to it twice (fixed points of the budget cut the proposals of every real
// frame on a machine where the stages before them took half the budget).
TEST(FrameBudgetTest, StageDeadlinesAreTheirSharesOfTheTimeLeft) {
  using std::chrono::hours;
  using std::chrono::minutes;
  using std::chrono::seconds;
  constexpr double kHourMs = 3'600'000;
  const FrameBudgetParams shares{.proposals_share = 0.5, .regression_share = 0.75};
  // A fresh hour: the proposals may use half of it, the regression three quarters.
  Clock::time_point before = Clock::now();
  const FrameBudget fresh(before, kHourMs, shares);
  ASSERT_TRUE(fresh.limited());
  EXPECT_EQ(fresh.end() - before, hours(1));
  EXPECT_GE(fresh.ProposalsDeadline() - before, minutes(30));
  EXPECT_LE(fresh.ProposalsDeadline() - before, minutes(30) + seconds(1));
  EXPECT_GE(fresh.RegressionDeadline() - before, minutes(45));
  EXPECT_LE(fresh.RegressionDeadline() - before, minutes(45) + seconds(1));
  // 40 minutes already spent: the shares are of the 20 left.
  before = Clock::now();
  const FrameBudget spent(before - minutes(40), kHourMs, shares);
  EXPECT_GE(spent.ProposalsDeadline() - before, minutes(10));
  EXPECT_LE(spent.ProposalsDeadline() - before, minutes(10) + seconds(1));
  EXPECT_GE(spent.RegressionDeadline() - before, minutes(15));
  EXPECT_LE(spent.RegressionDeadline() - before, minutes(15) + seconds(1));
  // All spent: the deadlines are the budget's end, already past.
  const FrameBudget over(Clock::now() - hours(2), kHourMs, shares);
  EXPECT_EQ(over.ProposalsDeadline(), over.end());
  EXPECT_EQ(over.RegressionDeadline(), over.end());
}

TEST(FrameBudgetTest, ShareOfRemainingSplitsTheTimeLeftByWeight) {
  EXPECT_EQ(ShareOfRemaining(Clock::time_point::max(), 1, 4), Clock::time_point::max());
  const Clock::time_point past = Clock::now() - std::chrono::seconds(1);
  EXPECT_EQ(ShareOfRemaining(past, 1, 4), past);  // nothing left to share
  const Clock::time_point before = Clock::now();
  const Clock::time_point stage_end = before + std::chrono::hours(1);
  const Clock::time_point quarter = ShareOfRemaining(stage_end, 1, 4);
  // A quarter of the hour left from "now" (taken inside the call, a little after `before`).
  EXPECT_GE(quarter - before, std::chrono::minutes(15) - std::chrono::seconds(1));
  EXPECT_LE(quarter - before, std::chrono::minutes(15) + std::chrono::seconds(1));
  EXPECT_EQ(ShareOfRemaining(stage_end, 4, 4), stage_end);  // the last piece gets all the rest
}

TEST(FrameBudgetTest, PlannedInTurnEndsEachPieceWhenItsTurnWould) {
  const std::vector<double> weights{1, 2, 1};
  for (const Clock::time_point d : PlannedInTurn(Clock::time_point::max(), weights))
    EXPECT_EQ(d, Clock::time_point::max());
  const Clock::time_point past = Clock::now() - std::chrono::seconds(1);
  for (const Clock::time_point d : PlannedInTurn(past, weights)) EXPECT_EQ(d, past);
  const Clock::time_point before = Clock::now();
  const Clock::time_point stage_end = before + std::chrono::hours(1);
  const std::vector<Clock::time_point> planned = PlannedInTurn(stage_end, weights);
  ASSERT_EQ(planned.size(), 3u);
  // A quarter, three quarters and all of the hour from "now" (taken inside the call).
  EXPECT_GE(planned[0] - before, std::chrono::minutes(15) - std::chrono::seconds(1));
  EXPECT_LE(planned[0] - before, std::chrono::minutes(15) + std::chrono::seconds(1));
  EXPECT_GE(planned[1] - before, std::chrono::minutes(45) - std::chrono::seconds(1));
  EXPECT_LE(planned[1] - before, std::chrono::minutes(45) + std::chrono::seconds(1));
  EXPECT_EQ(planned[2], stage_end);
  // No weight at all: nothing to share by, every piece may use the whole stage.
  for (const Clock::time_point d : PlannedInTurn(stage_end, {0, 0})) EXPECT_EQ(d, stage_end);
}

class DetectBudgetTest : public TinyDetectorTest {
 protected:
  const cv::Mat3b frame_ = RoadFrame(512, 256);
};

TEST_F(DetectBudgetTest, AGenerousBudgetChangesNothing) {
  DetectOptions budgeted;
  budgeted.budget_ms = 600'000;  // ten minutes: never reached by a 512 x 256 frame
  const Result<Detection> with = detector_->Detect(frame_, budgeted);
  const Result<Detection> without = detector_->Detect(frame_, DetectOptions{});
  ASSERT_TRUE(with.ok() && without.ok());
  EXPECT_FALSE(with->degraded());
  ASSERT_EQ(with->proposals.size(), without->proposals.size());
  ASSERT_GT(without->proposals.size(), 0u);
  for (size_t i = 0; i < without->proposals.size(); ++i) {
    EXPECT_EQ(with->proposals[i].box, without->proposals[i].box) << i;
    EXPECT_EQ(with->proposals[i].fused, without->proposals[i].fused) << i;
  }
  EXPECT_EQ(cv::norm(with->probability, without->probability, cv::NORM_INF), 0.0);
}

// A budget far below what the whole stages take: every region's scan deadline has passed before
// it starts, so no window is scored. The frame still gets a valid (empty) answer that says so.
TEST_F(DetectBudgetTest, AnExhaustedBudgetDegradesTheProposalsAndSaysSo) {
  DetectOptions options;
  options.budget_ms = 1e-3;
  const Result<Detection> detection = detector_->Detect(frame_, options);
  ASSERT_TRUE(detection.ok()) << detection.status().ToString();
  EXPECT_TRUE(detection->degraded());
  EXPECT_NE(
      std::find(detection->degraded_stages.begin(), detection->degraded_stages.end(), "proposals"),
      detection->degraded_stages.end());
  EXPECT_TRUE(detection->proposals.empty());
  EXPECT_EQ(detection->probability.size(), frame_.size());
  // This bundle's occlusion map is the untrained mean-Ê fallback (no trees to cut short), so
  // the occlusion stage is not said to be degraded; a trained one is (BenchCliTest).
  ASSERT_FALSE(detector_->bundle().occlusion.trained());
  EXPECT_EQ(
      std::find(detection->degraded_stages.begin(), detection->degraded_stages.end(), "occlusion"),
      detection->degraded_stages.end());
}

// The regression deadline alone: proposals are complete, none is regressed.
TEST_F(DetectBudgetTest, RegressionPastItsDeadlineDropsTheUnscoredProposals) {
  const FrameGeometry geometry = GeometryForFrame(detector_->bundle(), frame_.cols, frame_.rows);
  const ModelBundle& bundle = detector_->bundle();
  const Result<OcclusionEdges> computed = ComputeOcclusionEdges(
      frame_, geometry.regions, *bundle.edges, &bundle.occlusion, bundle.params, true);
  ASSERT_TRUE(computed.ok()) << computed.status().ToString();
  const OcclusionEdges& oaocc = *computed;
  const ProposalSet proposals = ProposeBoxes(
      oaocc, geometry.regions, bundle.params.boxes,
      DetectorProposalOptions(bundle.params, geometry.regions.num_layers()), geometry.size_filter);
  ASSERT_GT(proposals.boxes.size(), 0u);
  const RegressedProposals late =
      RegressProposals(bundle, frame_, oaocc, geometry.regions, proposals, nullptr,
                       {.deadline = Clock::now() - std::chrono::seconds(1)});
  EXPECT_TRUE(late.truncated);
  EXPECT_EQ(late.dropped, proposals.boxes.size());
  EXPECT_TRUE(late.proposals.boxes.empty());
  EXPECT_TRUE(late.ordr.empty() && late.obdr.empty());
  const RegressedProposals full =
      RegressProposals(bundle, frame_, oaocc, geometry.regions, proposals);
  EXPECT_FALSE(full.truncated);
  EXPECT_EQ(full.ordr.size(), proposals.boxes.size());
}

// --threads-per-request: the window scans, features and regressors split their work, never the
// result (bit-identical, as every piece writes only its own rows).
TEST_F(DetectBudgetTest, ThreadsPerRequestGiveTheSameResult) {
  DetectOptions one;
  DetectOptions three;
  three.threads = 3;
  const Result<Detection> a = detector_->Detect(frame_, one);
  const Result<Detection> b = detector_->Detect(frame_, three);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->proposals.size(), b->proposals.size());
  for (size_t i = 0; i < a->proposals.size(); ++i) {
    EXPECT_EQ(a->proposals[i].box, b->proposals[i].box) << i;
    EXPECT_EQ(a->proposals[i].ordr, b->proposals[i].ordr) << i;
    EXPECT_EQ(a->proposals[i].obdr, b->proposals[i].obdr) << i;
  }
  EXPECT_EQ(cv::norm(a->probability, b->probability, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace tod
