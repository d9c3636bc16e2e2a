// Test doubles of tod::Detector for the engine tests: a detector whose Detect() waits until the
// test opens a gate, so queueing, deadlines and draining can be driven step by step.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/pipeline/detector.h"

namespace tod::server::testing {

// Obstacles = bounding box of pixels darker than 60 (if any); P = 0.25 everywhere.
class GatedDetector : public Detector {
 public:
  explicit GatedDetector(std::string version, bool open = true) : open_(open) {
    info_.name = "gated";
    info_.version = std::move(version);
  }

  Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options) const override {
    {
      std::unique_lock lock(mutex_);
      ++started_;
      changed_.notify_all();
      changed_.wait(lock, [this] { return open_; });
    }
    // One stage boundary, after the gate: a request cancelled while it waited stops here.
    if (options.cancelled) {
      if (Status stop = options.cancelled(); !stop.ok()) return stop;
    }
    Detection detection;
    detection.width = bgr.cols;
    detection.height = bgr.rows;
    cv::Mat1b grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    const cv::Rect dark = cv::boundingRect(grey < 60);
    if (dark.area() > 0) {
      detection.obstacles.push_back({Box::FromRect(dark), dark.area(), 0.9f, 0.8f});
    }
    for (int i = 0; i < options.max_proposals && i < 3; ++i) {
      detection.proposals.push_back({Box{i, i, 4, 4}, 1.f - 0.1f * i, 0.5f, 0.25f});
    }
    if (options.want_probability_map) detection.probability = cv::Mat1f(bgr.size(), 0.25f);
    // As the real detector does: a frame of a camera adds to that camera's estimate.
    if (options.camera) {
      detection.horizon.source = HorizonSource::kCamera;
      detection.horizon.camera_frames = options.camera->Observe(0.5).frames;
    }
    detection.timings = {{"fake_stage", 0.5}};
    return detection;
  }
  const ModelInfo& info() const override { return info_; }

  void Open() {
    std::lock_guard lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }
  // Waits until `count` Detect calls have started; false after 5 s.
  bool WaitStarted(int count) const {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(5), [&] { return started_ >= count; });
  }
  int started() const {
    std::lock_guard lock(mutex_);
    return started_;
  }

 private:
  ModelInfo info_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  mutable int started_ = 0;
  bool open_;
};

}  // namespace tod::server::testing
