// The time one frame may take (issue 11, `--frame-budget-ms`), and how the stages share it.
// Edges and superpixels cost what the frame's pixels cost (bounded by the pixel limit) and
// always run whole; the three stages whose cost grows with the frame's content degrade when
// their share runs out, in a defined way:
//  - occlusion: the classifier's forest is walked for all superpixel pairs a piece of trees at a
//    time (OcclusionClassifier::Paint) and stops between pieces: every pair's probability is
//    the mean of fewer trees (a frame of many small superpixels has many pairs);
//  - proposals: the window scan of each region stops handing out grid columns at the region's
//    deadline (the columns left out are scattered over shapes and positions: a coarser grid);
//    the far regions, scanned last, lose windows first (a request with several threads scans
//    the regions side by side, each by the deadline it would have in turn: PlannedInTurn);
//  - features and regression: proposals are regressed in objectness order, in chunks; those not
//    reached by the deadline are left out of the map.
// A frame that degrades says so (Detection::degraded_stages) and the server counts it.
#pragma once

#include <chrono>
#include <vector>

namespace tod {

struct FrameBudgetParams {
  // The shares of the time left when a stage starts that the occlusion classifier's forest,
  // the proposals, then the features + ORDR, may use. The rest is left for OBDR on the gated
  // boxes, the map and its encoding (a few tens of ms on 2 MP frames). Shares of the time left,
  // not fixed points of the budget: the whole stages before them (decode, edges, superpixels)
  // take what the machine makes them take, and fixed points (proposals by 55 % of the budget,
  // regression by 85 %) cut the proposals of every real frame on a machine where the stages
  // before them took 1000 of the 2000 ms
  // (docs/findings.md#frame-budget-as-shares-of-the-time-left). A real frame's occlusion stage
  // needs about a quarter of the time left after the superpixels.
  double occlusion_share = 0.35;
  double proposals_share = 0.5;
  double regression_share = 0.75;
};

class FrameBudget {
 public:
  using Clock = std::chrono::steady_clock;
  // No budget: every deadline is Clock::time_point::max().
  FrameBudget() = default;
  // budget_ms <= 0 means no budget.
  FrameBudget(Clock::time_point start, double budget_ms, const FrameBudgetParams& params = {});

  bool limited() const { return end_ != Clock::time_point::max(); }
  Clock::time_point end() const { return end_; }
  // Asked when the stage starts: now + its share of the time left until end() (end() itself
  // when that has passed); Clock::time_point::max() without a budget.
  Clock::time_point OcclusionDeadline() const;
  Clock::time_point ProposalsDeadline() const;
  Clock::time_point RegressionDeadline() const;

 private:
  Clock::time_point end_ = Clock::time_point::max();
  FrameBudgetParams params_;
};

// What is left of a frame budget (budget_ms, <= 0: none) once spent_ms went on work before
// Detect (decoding): still a budget, even when nothing is left, so that Detect then degrades
// as far as it can instead of running unbounded.
double BudgetLeftMs(double budget_ms, double spent_ms);

// Deadlines for consecutive pieces of work sharing [now, stage_deadline): piece i gets
// now + (stage_deadline - now) * weight_i / (weight_i + ... + weight_last), asked again when
// piece i starts, so time a piece leaves unused passes on to the next ones.
std::chrono::steady_clock::time_point ShareOfRemaining(
    std::chrono::steady_clock::time_point stage_deadline, double weight, double remaining_weight);

// Deadlines for pieces of work planned in turn over [now, stage_deadline) but run at once: piece
// i must end by now + (stage_deadline - now) * (weight_0 + ... + weight_i) / (sum of weights),
// when it would end if the pieces ran one after another at a steady pace. Running them side by
// side only lets a piece end sooner, so the last pieces are still the first to lose work.
std::vector<std::chrono::steady_clock::time_point> PlannedInTurn(
    std::chrono::steady_clock::time_point stage_deadline, const std::vector<double>& weights);

}  // namespace tod
