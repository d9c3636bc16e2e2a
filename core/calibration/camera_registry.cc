#include "core/calibration/camera_registry.h"

#include <algorithm>

namespace tod {

CameraTrack::View CameraTrack::Observe(std::optional<double> frame_row) {
  std::lock_guard lock(mu_);
  if (frame_row) horizon_.Add(*frame_row);
  return {horizon_.Estimate(), horizon_.frames()};
}

Status CheckCameraId(std::string_view camera_id, const CameraRegistryParams& params) {
  if (camera_id.size() > params.max_id_bytes) {
    return Status::InvalidArgument("camera_id: " + std::to_string(camera_id.size()) +
                                   " bytes is over the limit of " +
                                   std::to_string(params.max_id_bytes));
  }
  const auto bad =
      std::find_if(camera_id.begin(), camera_id.end(), [](char c) { return c <= ' ' || c > '~'; });
  if (bad != camera_id.end()) {
    return Status::InvalidArgument("camera_id: byte " + std::to_string(bad - camera_id.begin()) +
                                   " is not printable ASCII (spaces are not allowed either)");
  }
  return Status::Ok();
}

void CameraRegistry::ForgetIdle(Clock::time_point now) {
  const auto idle = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(params_.idle_seconds));
  for (auto it = cameras_.begin(); it != cameras_.end();) {
    if (now - it->second.last_seen > idle) {
      it = cameras_.erase(it);
      ++forgotten_;
    } else {
      ++it;
    }
  }
}

std::shared_ptr<CameraTrack> CameraRegistry::Track(const std::string& camera_id,
                                                   Clock::time_point now) {
  std::lock_guard lock(mu_);
  if (auto it = cameras_.find(camera_id); it != cameras_.end()) {
    it->second.last_seen = now;
    return it->second.track;
  }
  // A new camera: the idle ones go first, then (when still full) the least recently seen.
  // A linear scan: it runs once per new camera, over at most max_cameras entries.
  ForgetIdle(now);
  if (params_.max_cameras == 0) return std::make_shared<CameraTrack>();
  if (cameras_.size() >= params_.max_cameras) {
    const auto oldest = std::min_element(
        cameras_.begin(), cameras_.end(),
        [](const auto& a, const auto& b) { return a.second.last_seen < b.second.last_seen; });
    cameras_.erase(oldest);
    ++forgotten_;
  }
  Entry& entry = cameras_[camera_id];
  entry.track = std::make_shared<CameraTrack>();
  entry.last_seen = now;
  return entry.track;
}

std::size_t CameraRegistry::size() const {
  std::lock_guard lock(mu_);
  return cameras_.size();
}

long long CameraRegistry::forgotten() const {
  std::lock_guard lock(mu_);
  return forgotten_;
}

}  // namespace tod
