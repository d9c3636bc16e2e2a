// The cameras a server has seen, each with its horizon over the frames it sent (camera_id on a
// request; a DetectStream is one camera). Bounded: at most max_cameras, each of fixed size
// (CameraHorizon), the least recently seen one forgotten to admit a new one, and any camera not
// seen for idle_seconds forgotten. Thread-safe.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/calibration/camera_horizon.h"

namespace tod {

// One camera's estimate, shared by the requests of that camera.
class CameraTrack {
 public:
  CameraTrack() = default;
  // A track that has already seen these frames (an evaluation replaying a camera's split).
  explicit CameraTrack(const CameraHorizon& seen) : horizon_(seen) {}
  // Adds a frame's estimate when there is one, then returns the camera's median and its frames
  // (in whatever unit the caller keeps: ChooseHorizon uses shares of the frame's height).
  struct View {
    std::optional<double> row;
    long long frames = 0;
  };
  View Observe(std::optional<double> frame_row);

 private:
  std::mutex mu_;
  CameraHorizon horizon_;
};

struct CameraRegistryParams {
  std::size_t max_cameras = 1024;
  double idle_seconds = 600;
  std::size_t max_id_bytes = 128;  // longer camera_id values are refused by the front ends
};

// OK when `camera_id` can name a camera: at most params.max_id_bytes of printable ASCII and no
// spaces (it is logged and used as a map key); empty is fine (no camera). InvalidArgument else.
Status CheckCameraId(std::string_view camera_id, const CameraRegistryParams& params);

class CameraRegistry {
 public:
  using Clock = std::chrono::steady_clock;
  explicit CameraRegistry(CameraRegistryParams params = {}) : params_(params) {}

  // The camera's track, made when new. `now` is injectable for tests.
  std::shared_ptr<CameraTrack> Track(const std::string& camera_id, Clock::time_point now);
  std::shared_ptr<CameraTrack> Track(const std::string& camera_id) {
    return Track(camera_id, Clock::now());
  }
  std::size_t size() const;
  long long forgotten() const;  // cameras dropped (idle or to make room) since start
  const CameraRegistryParams& params() const { return params_; }

 private:
  struct Entry {
    std::shared_ptr<CameraTrack> track;
    Clock::time_point last_seen;
  };
  void ForgetIdle(Clock::time_point now);  // mu_ held

  const CameraRegistryParams params_;
  mutable std::mutex mu_;
  std::map<std::string, Entry> cameras_;
  long long forgotten_ = 0;
};

}  // namespace tod
