#include "core/pipeline/frame_budget.h"

#include <algorithm>

namespace tod {

namespace {

FrameBudget::Clock::time_point At(FrameBudget::Clock::time_point start, double ms) {
  return start + std::chrono::duration_cast<FrameBudget::Clock::duration>(
                     std::chrono::duration<double, std::milli>(ms));
}

}  // namespace

FrameBudget::FrameBudget(Clock::time_point start, double budget_ms, const FrameBudgetParams& params)
    : params_(params) {
  if (budget_ms > 0) end_ = At(start, budget_ms);
}

FrameBudget::Clock::time_point FrameBudget::OcclusionDeadline() const {
  return ShareOfRemaining(end_, std::clamp(params_.occlusion_share, 0.0, 1.0), 1.0);
}

FrameBudget::Clock::time_point FrameBudget::ProposalsDeadline() const {
  return ShareOfRemaining(end_, std::clamp(params_.proposals_share, 0.0, 1.0), 1.0);
}

FrameBudget::Clock::time_point FrameBudget::RegressionDeadline() const {
  return ShareOfRemaining(end_, std::clamp(params_.regression_share, 0.0, 1.0), 1.0);
}

double BudgetLeftMs(double budget_ms, double spent_ms) {
  if (!(budget_ms > 0)) return budget_ms;
  constexpr double kExhausted = 1e-3;  // positive: a budget, past at once
  return std::max(kExhausted, budget_ms - spent_ms);
}

std::chrono::steady_clock::time_point ShareOfRemaining(
    std::chrono::steady_clock::time_point stage_deadline, double weight, double remaining_weight) {
  using Clock = std::chrono::steady_clock;
  if (stage_deadline == Clock::time_point::max()) return stage_deadline;
  const Clock::time_point now = Clock::now();
  if (now >= stage_deadline || !(remaining_weight > 0)) return stage_deadline;
  const double share = std::clamp(weight / remaining_weight, 0.0, 1.0);
  return now + std::chrono::duration_cast<Clock::duration>((stage_deadline - now) * share);
}

std::vector<std::chrono::steady_clock::time_point> PlannedInTurn(
    std::chrono::steady_clock::time_point stage_deadline, const std::vector<double>& weights) {
  using Clock = std::chrono::steady_clock;
  std::vector<Clock::time_point> deadlines(weights.size(), stage_deadline);
  if (stage_deadline == Clock::time_point::max()) return deadlines;
  const Clock::time_point now = Clock::now();
  double total = 0;
  for (const double w : weights) total += std::max(0.0, w);
  if (now >= stage_deadline || !(total > 0)) return deadlines;
  double before = 0;
  for (std::size_t i = 0; i + 1 < weights.size(); ++i) {
    before += std::max(0.0, weights[i]);
    const double share = std::clamp(before / total, 0.0, 1.0);
    deadlines[i] =
        now + std::chrono::duration_cast<Clock::duration>((stage_deadline - now) * share);
  }
  return deadlines;  // the last piece ends with the stage
}

}  // namespace tod
