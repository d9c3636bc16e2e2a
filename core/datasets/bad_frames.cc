#include "core/datasets/bad_frames.h"

namespace tod {

Result<BadFramePolicy> ParseBadFramePolicy(const std::string& text) {
  if (text == "fail") return BadFramePolicy::kFail;
  if (text == "skip") return BadFramePolicy::kSkip;
  return Status::InvalidArgument("--on-bad-frame must be fail or skip, got '" + text + "'");
}

Status ApplyBadFramePolicy(const std::vector<Status>& per_frame,
                           const std::function<std::string(int)>& frame_name, BadFramePolicy policy,
                           std::vector<SkippedFrame>* skipped) {
  for (std::size_t i = 0; i < per_frame.size(); ++i) {
    const Status& s = per_frame[i];
    if (s.ok()) continue;
    const std::string name = frame_name(static_cast<int>(i));
    if (policy == BadFramePolicy::kFail) {
      return s.WithContext("frame " + name + " (--on-bad-frame skip leaves such frames out)");
    }
    if (skipped == nullptr) return Status::Internal("ApplyBadFramePolicy: skipped list is null");
    skipped->push_back({name, s.message()});
  }
  return Status::Ok();
}

nlohmann::json SkippedFramesToJson(const std::vector<SkippedFrame>& skipped) {
  nlohmann::json frames = nlohmann::json::array();
  for (const SkippedFrame& f : skipped)
    frames.push_back({{"frame", f.frame}, {"reason", f.reason}});
  return {{"count", skipped.size()}, {"frames", frames}};
}

}  // namespace tod
