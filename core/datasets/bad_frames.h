// What a training or evaluation run does with a frame that cannot be read or processed:
// `--on-bad-frame fail` (default) stops with that frame's error; `skip` leaves it out, lists it
// with the reason and counts it, so one corrupt file does not abort a run over a thousand frames.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod {

enum class BadFramePolicy { kFail, kSkip };

// "fail" or "skip"; anything else is an error naming the value.
Result<BadFramePolicy> ParseBadFramePolicy(const std::string& text);

struct SkippedFrame {
  std::string frame;
  std::string reason;
};

// Applies `policy` to one Status per frame (frame_name(i) names frame i in messages). kFail: the
// first error, prefixed with its frame's name. kSkip: Ok, and every failed frame appended to
// `skipped` (which may not be null then).
Status ApplyBadFramePolicy(const std::vector<Status>& per_frame,
                           const std::function<std::string(int)>& frame_name, BadFramePolicy policy,
                           std::vector<SkippedFrame>* skipped);

// {"count": n, "frames": [{"frame": ..., "reason": ...}, ...]}
nlohmann::json SkippedFramesToJson(const std::vector<SkippedFrame>& skipped);

}  // namespace tod
