// Wall-clock time of named pipeline stages, reported per frame from the start (issue: speed).
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace tod {

using StageTimes = std::vector<std::pair<std::string, double>>;  // (stage, milliseconds), in order

class StageTimer {
 public:
  StageTimer() : last_(Clock::now()) {}
  // Closes the stage that began at construction or at the previous Mark().
  void Mark(std::string stage) {
    const auto now = Clock::now();
    times_.emplace_back(std::move(stage),
                        std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }
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
};

}  // namespace tod
