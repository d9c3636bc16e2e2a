// Wall-clock time of named pipeline stages, reported per frame from the start (issue: speed).
#pragma once

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/base/status.h"

namespace tod {

using StageTimes = std::vector<std::pair<std::string, double>>;  // (stage, milliseconds), in order

// Every stage boundary of the pipeline already goes through Mark(), so the timer also carries
// the caller's cancellation check: Mark() asks it, and once it answers non-OK, stopped() keeps
// that Status and the stage functions return early (they test stopped() after each Mark).
class StageTimer {
 public:
  using Check = std::function<Status()>;
  StageTimer() : last_(Clock::now()) {}
  explicit StageTimer(Check check) : last_(Clock::now()), check_(std::move(check)) {}
  // Closes the stage that began at construction or at the previous Mark(), then asks the check.
  void Mark(std::string stage) {
    const auto now = Clock::now();
    times_.emplace_back(std::move(stage),
                        std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
    if (check_ && stopped_.ok()) stopped_ = check_();
  }
  // Records `stage` as taking `ms` of the time since the previous mark (at most all of it) and
  // leaves the rest to the next Mark(): for two stages that ran interleaved. Asks the check.
  void MarkPart(std::string stage, double ms) {
    const double since_last =
        std::chrono::duration<double, std::milli>(Clock::now() - last_).count();
    const double part = std::clamp(ms, 0.0, since_last);
    times_.emplace_back(std::move(stage), part);
    last_ += std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double, std::milli>(part));
    if (check_ && stopped_.ok()) stopped_ = check_();
  }
  // OK until the check asked to stop; then the check's Status (Cancelled, DeadlineExceeded, ...).
  const Status& stopped() const { return stopped_; }
  void Restart() { last_ = Clock::now(); }
  const StageTimes& times() const { return times_; }
  double total_ms() const {
    double sum = 0;
    for (const auto& [name, ms] : times_) sum += ms;
    return sum;
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point last_;
  StageTimes times_;
  Check check_;
  Status stopped_;
};

}  // namespace tod
