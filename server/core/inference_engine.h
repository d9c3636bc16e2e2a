// Admission control and the worker pool, shared by the gRPC and REST frontends (Triton-style:
// frontends only translate; everything about queueing, deadlines and draining lives here).
//
// A request is checked (readiness, byte size, image header and pixel count) when submitted and
// refused at once if it cannot be served; otherwise it waits in one bounded FIFO queue for one of
// N workers. A worker skips a request whose deadline passed or whose caller gave up while it was
// queued, decodes the image, takes a snapshot of the current model and runs the pipeline, asking
// the request's Cancellation (and its deadline) at every stage boundary.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/base/status.h"
#include "core/calibration/camera_registry.h"
#include "core/pipeline/detector.h"
#include "server/core/cancellation.h"
#include "server/core/engine_observer.h"
#include "server/core/image_codec.h"
#include "server/core/model_holder.h"
#include "server/core/rejection.h"

namespace tod::server {

struct InferenceRequest {
  std::string_view image;  // encoded JPEG/PNG; must stay valid until the completion has run
  std::string model;       // the model's name (ModelHolder::Find); empty: the default model
  DetectOptions options;
  bool encode_map_png = true;
  std::optional<std::chrono::steady_clock::time_point> deadline;
  // Set by the front end when its caller gives up; null: the engine makes one (deadline, drain).
  std::shared_ptr<Cancellation> cancellation;
  // The camera the frame comes from: its horizon estimate is kept in the engine's registry
  // (CheckCameraId bounds it at admission). Empty: `stream_camera`, the track a DetectStream
  // keeps for its own frames, or none (the frame is calibrated alone).
  std::string camera_id;
  std::shared_ptr<CameraTrack> stream_camera;
};

struct InferenceResult {
  Status status;
  Rejection rejection = Rejection::kNone;
  Detection detection;                       // valid when status.ok()
  std::string map_png;                       // when requested and status.ok()
  std::optional<CancelReason> cancelled;     // why the work was stopped, when it was
  std::shared_ptr<const LoadedModel> model;  // the model that served the request
  StageTimes timings;                        // "queue", "decode", pipeline stages, "encode_map"
  double total_ms = 0;                       // submission to completion
};

using Completion = std::function<void(InferenceResult)>;

// A request's budget_ms option, when set, must lie in [1, this].
inline constexpr long long kMaxRequestBudgetMs = 600'000;
// A request's max_proposals option must lie in [0, this], on gRPC and REST alike (the proto
// documents the range; the REST query parser and the engine's admission check both use this).
inline constexpr int kMaxRequestProposals = 10'000;

struct EngineConfig {
  int workers = 1;
  // Frame budget (core/pipeline/frame_budget.h), counted from when a worker takes the request
  // (decode included); a request's budget_ms may lower it. <= 0: none.
  double frame_budget_ms = 2000;
  int threads_per_request = 1;  // cores one request may use (DetectOptions::threads)
  int queue_capacity = 16;      // requests waiting (not counting the ones running)
  ImageLimits limits;
  CameraRegistryParams cameras;  // the cameras whose horizon the engine keeps
};

class InferenceEngine {
 public:
  // `models` and `observer` (nullable: nobody listens) must outlive the engine.
  InferenceEngine(EngineConfig config, const ModelHolder& models, EngineObserver* observer);
  ~InferenceEngine();
  InferenceEngine(const InferenceEngine&) = delete;
  InferenceEngine& operator=(const InferenceEngine&) = delete;

  void Start();
  // Runs `done` exactly once: inline when the request is refused at admission, otherwise on a
  // worker thread.
  void Submit(const InferenceRequest& request, Completion done);

  // A model is loaded and the engine is not draining.
  bool Ready() const;
  // From now on every new request is refused with UNAVAILABLE; queued ones still run.
  void BeginDrain();
  bool draining() const;
  // Waits until nothing is queued or running; false when `deadline` came first.
  bool WaitIdle(std::chrono::steady_clock::time_point deadline);
  // The drain timeout: queued requests complete at once with UNAVAILABLE, running ones are
  // cancelled (they stop at their next stage boundary, also with UNAVAILABLE); new ones are
  // refused. Returns at once; WaitIdle() then tells when the running ones have stopped.
  void CancelAll(CancelReason reason);
  // Requests still queued complete with UNAVAILABLE; running ones finish; workers are joined.
  void Stop();

  size_t queue_depth() const;
  size_t cameras_tracked() const { return cameras_.size(); }
  const EngineConfig& config() const { return config_; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Job {
    InferenceRequest request;
    Completion done;
    Clock::time_point submitted;
    std::shared_ptr<Cancellation> cancellation;  // never null
  };

  void WorkerLoop();
  InferenceResult Run(const Job& job) const;
  void Finish(Completion& done, InferenceResult result, Clock::time_point submitted) const;
  Status ValidateOptions(const DetectOptions& options) const;
  // Why `request` is refused before it takes a queue slot (not ready, bad options, over the
  // byte or pixel limits, not an image), or nothing.
  std::optional<InferenceResult> AdmissionRefusal(const InferenceRequest& request) const;

  const EngineConfig config_;
  const ModelHolder& models_;
  EngineObserver* const observer_;
  // Thread-safe on its own; mutable because looking a camera up refreshes it (Run is const).
  mutable CameraRegistry cameras_;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable work_available_;
  std::condition_variable idle_;
  std::deque<Job> queue_;
  int running_ = 0;
  std::vector<std::shared_ptr<Cancellation>> running_cancellations_;  // of the running jobs
  bool draining_ = false;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace tod::server
