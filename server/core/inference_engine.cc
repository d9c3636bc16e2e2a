#include "server/core/inference_engine.h"

#include <exception>
#include <opencv2/core/utility.hpp>
#include <utility>

#include "core/pipeline/frame_budget.h"
#include "server/core/image_header.h"

namespace tod::server {
namespace {

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

InferenceResult Refusal(Status status, Rejection rejection) {
  InferenceResult result;
  result.status = std::move(status);
  result.rejection = rejection;
  return result;
}

// A request whose work was stopped (or never started) because of `reason`.
InferenceResult Stopped(CancelReason reason, const std::string& where) {
  InferenceResult result =
      Refusal(CancelledStatus(reason, where),
              reason == CancelReason::kDeadline ? Rejection::kDeadline : Rejection::kCancelled);
  result.cancelled = reason;
  return result;
}

// Why the job must stop now, if it must: its caller gave up, the drain timeout came, or its
// deadline passed (which is then recorded in the Cancellation, so the first reason sticks).
std::optional<CancelReason> StopReason(
    Cancellation& cancellation,
    const std::optional<std::chrono::steady_clock::time_point>& deadline) {
  if (!cancellation.cancelled() && deadline && std::chrono::steady_clock::now() >= *deadline) {
    cancellation.Cancel(CancelReason::kDeadline);
  }
  return cancellation.reason();
}

// The server's budget, lowered by the request's when it sets one (0 = unset; <= 0: no budget).
double EffectiveBudgetMs(double server_ms, double request_ms) {
  if (request_ms <= 0) return server_ms;
  if (server_ms <= 0) return request_ms;
  return std::min(server_ms, request_ms);
}

// The refusal for an image that did not decode: too large, or not an image.
InferenceResult DecodeRefusal(const Status& status) {
  const Rejection why =
      status.code() == StatusCode::kResourceExhausted ? Rejection::kTooLarge : Rejection::kBadImage;
  return Refusal(status, why);
}

// The pipeline's options for a request: its own, the server's threads per request, and the
// frame budget (the server's, lowered by the request's) less what decoding already spent.
DetectOptions PipelineOptions(const InferenceRequest& request, const EngineConfig& config,
                              std::chrono::steady_clock::time_point started) {
  DetectOptions options = request.options;
  options.want_probability_map = request.encode_map_png;
  options.threads = config.threads_per_request;
  options.budget_ms = EffectiveBudgetMs(config.frame_budget_ms, request.options.budget_ms);
  options.budget_ms = BudgetLeftMs(options.budget_ms, MillisecondsSince(started));
  return options;
}

// Runs the detector into `detection`; what to answer instead when it stopped or failed. An
// exception from the pipeline becomes this request's INTERNAL error, never the worker's end.
std::optional<InferenceResult> RunDetector(const Detector& detector, const cv::Mat3b& image,
                                           const DetectOptions& options,
                                           const Cancellation& cancellation, const int& boundaries,
                                           Detection& detection) {
  try {
    Result<Detection> run = detector.Detect(image, options);
    if (const std::optional<CancelReason> reason = cancellation.reason(); !run.ok() && reason) {
      return Stopped(*reason, "while the pipeline ran (at its stage boundary " +
                                  std::to_string(boundaries) + ")");
    }
    if (!run.ok()) {
      const Rejection why = run.status().code() == StatusCode::kInvalidArgument
                                ? Rejection::kBadImage
                                : Rejection::kInternal;
      return Refusal(run.status(), why);
    }
    detection = std::move(*run);
  } catch (const std::exception& e) {
    return Refusal(Status::Internal(std::string("pipeline failed: ") + e.what()),
                   Rejection::kInternal);
  }
  return std::nullopt;
}

}  // namespace

InferenceEngine::InferenceEngine(EngineConfig config, const ModelHolder& models,
                                 EngineObserver* observer)
    : config_(std::move(config)), models_(models), observer_(observer), cameras_(config_.cameras) {}

InferenceEngine::~InferenceEngine() { Stop(); }

void InferenceEngine::Start() {
  std::lock_guard lock(mutex_);
  if (!workers_.empty() || stopping_) return;
  for (int i = 0; i < config_.workers; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

Status InferenceEngine::ValidateOptions(const DetectOptions& options) const {
  if (options.max_proposals < 0 || options.max_proposals > kMaxRequestProposals) {
    return Status::InvalidArgument("max_proposals: " + std::to_string(options.max_proposals) +
                                   " is outside [0, " + std::to_string(kMaxRequestProposals) + "]");
  }
  if (!(options.obstacle_threshold >= 0.f && options.obstacle_threshold <= 1.f)) {
    return Status::InvalidArgument(
        "obstacle_threshold: " + std::to_string(options.obstacle_threshold) + " is outside [0, 1]");
  }
  if (!(options.min_obstacle_score >= 0.f && options.min_obstacle_score <= 1.f)) {
    return Status::InvalidArgument(
        "min_obstacle_score: " + std::to_string(options.min_obstacle_score) + " is outside [0, 1]");
  }
  // 0 = not set; otherwise a whole number of ms in range (also refuses NaN).
  if (options.budget_ms != 0 &&
      !(options.budget_ms >= 1 && options.budget_ms <= static_cast<double>(kMaxRequestBudgetMs))) {
    return Status::InvalidArgument("budget_ms: " + std::to_string(options.budget_ms) +
                                   " is outside [1, " + std::to_string(kMaxRequestBudgetMs) + "]");
  }
  return Status::Ok();
}

void InferenceEngine::Finish(Completion& done, InferenceResult result,
                             Clock::time_point submitted) const {
  result.total_ms = MillisecondsSince(submitted);
  if (observer_ != nullptr && result.rejection != Rejection::kNone) {
    observer_->OnRejected(result.rejection);
  }
  if (observer_ != nullptr && result.cancelled) observer_->OnCancelled(*result.cancelled);
  done(std::move(result));
}

std::optional<InferenceResult> InferenceEngine::AdmissionRefusal(
    const InferenceRequest& request) const {
  if (!Ready()) {
    return Refusal(Status::Unavailable(draining() ? "server is shutting down; retry elsewhere"
                                                  : "model not loaded yet; retry shortly"),
                   Rejection::kNotReady);
  }
  if (Status valid = ValidateOptions(request.options); !valid.ok()) {
    return Refusal(std::move(valid), Rejection::kBadRequest);
  }
  if (Status valid = CheckCameraId(request.camera_id, config_.cameras); !valid.ok()) {
    return Refusal(std::move(valid), Rejection::kBadRequest);
  }
  if (!request.model.empty() && models_.Find(request.model) == nullptr) {
    return Refusal(Status::NotFound("unknown model '" + request.model + "'"),
                   Rejection::kUnknownModel);
  }
  if (request.image.size() > config_.limits.max_bytes) {
    return Refusal(Status::ResourceExhausted("image: " + std::to_string(request.image.size()) +
                                             " bytes is over the limit of " +
                                             std::to_string(config_.limits.max_bytes) + " bytes"),
                   Rejection::kTooLarge);
  }
  const Result<ImageHeader> header = PeekImageHeader(request.image);
  if (!header.ok()) return Refusal(header.status(), Rejection::kBadImage);
  if (static_cast<long long>(header->size.width) * header->size.height >
      config_.limits.max_pixels) {
    return Refusal(Status::ResourceExhausted("image: " + std::to_string(header->size.width) + "x" +
                                             std::to_string(header->size.height) +
                                             " pixels is over the limit of " +
                                             std::to_string(config_.limits.max_pixels) + " pixels"),
                   Rejection::kTooLarge);
  }
  return std::nullopt;
}

void InferenceEngine::Submit(const InferenceRequest& request, Completion done) {
  const Clock::time_point submitted = Clock::now();
  // Cheap checks first, so a request that can never succeed does not take a queue slot.
  if (std::optional<InferenceResult> refusal = AdmissionRefusal(request)) {
    Finish(done, std::move(*refusal), submitted);
    return;
  }
  {
    std::unique_lock lock(mutex_);
    if (static_cast<int>(queue_.size()) >= config_.queue_capacity) {
      const size_t depth = queue_.size();
      lock.unlock();
      Finish(done,
             Refusal(Status::ResourceExhausted("server busy: the queue is full (" +
                                               std::to_string(depth) +
                                               " waiting); retry after a short pause"),
                     Rejection::kQueueFull),
             submitted);
      return;
    }
    std::shared_ptr<Cancellation> cancellation =
        request.cancellation ? request.cancellation : std::make_shared<Cancellation>();
    queue_.push_back(Job{request, std::move(done), submitted, std::move(cancellation)});
    if (observer_ != nullptr) observer_->OnAccepted(queue_.size());
  }
  work_available_.notify_one();
}

void InferenceEngine::WorkerLoop() {
  // Parallelism comes from the worker pool and --threads-per-request; OpenCV's pool (process-wide,
  // used by the edge classifier's row loop) gets the same per-request width, so that workers x
  // threads_per_request stays the number of busy cores.
  cv::setNumThreads(config_.threads_per_request);
  for (;;) {
    Job job;
    bool stop_now = false;
    {
      std::unique_lock lock(mutex_);
      work_available_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping and nothing left
      job = std::move(queue_.front());
      queue_.pop_front();
      ++running_;
      running_cancellations_.push_back(job.cancellation);
      stop_now = stopping_;
      if (observer_ != nullptr) observer_->OnQueueDepth(queue_.size());
    }
    InferenceResult result;
    if (stop_now) {  // Stop() came before this job could start
      result = Refusal(Status::Unavailable("server shut down before the request ran"),
                       Rejection::kNotReady);
    } else {
      result = Run(job);
    }
    // Out of the gauge before the answer goes out: a client that has its answer must never see
    // its request still in flight.
    if (observer_ != nullptr) observer_->OnFinished();
    Finish(job.done, std::move(result), job.submitted);
    {
      std::lock_guard lock(mutex_);
      --running_;
      std::erase(running_cancellations_, job.cancellation);
    }
    idle_.notify_all();
  }
}

InferenceResult InferenceEngine::Run(const Job& job) const {
  const double queue_ms = MillisecondsSince(job.submitted);
  if (observer_ != nullptr) observer_->OnStarted(queue_ms);
  const InferenceRequest& request = job.request;
  Cancellation& cancellation = *job.cancellation;
  if (const std::optional<CancelReason> reason = StopReason(cancellation, request.deadline)) {
    return Stopped(*reason, "after " + std::to_string(static_cast<int>(queue_ms)) +
                                " ms in the queue, before the request ran");
  }
  InferenceResult result;
  result.timings.emplace_back("queue", queue_ms);
  // This request's model, whatever reloads happen meanwhile.
  result.model = models_.Find(request.model);
  if (!result.model && request.model.empty()) {
    return Refusal(Status::Unavailable("no default model loaded"), Rejection::kNotReady);
  }
  if (!result.model) {  // unloaded while the request waited
    return Refusal(Status::NotFound("model '" + request.model + "' was unloaded"),
                   Rejection::kUnknownModel);
  }

  const Clock::time_point started = Clock::now();  // the frame budget counts from here
  StageTimer timer;
  Result<cv::Mat3b> image = DecodeImage(request.image, config_.limits);
  if (!image.ok()) return DecodeRefusal(image.status());
  timer.Mark("decode");
  result.timings.insert(result.timings.end(), timer.times().begin(), timer.times().end());
  if (const std::optional<CancelReason> reason = StopReason(cancellation, request.deadline)) {
    return Stopped(*reason, "after decoding");
  }

  DetectOptions options = PipelineOptions(request, config_, started);
  options.camera =
      request.camera_id.empty() ? request.stream_camera : cameras_.Track(request.camera_id);
  // Asked between the pipeline's stages; the Status it returns is only a signal here: the result
  // is rebuilt from the reason (RunDetector) so the message says where the work stopped.
  int boundaries = 0;  // stage boundaries passed, for the message
  options.cancelled = [&cancellation, &request, &boundaries] {
    ++boundaries;
    return StopReason(cancellation, request.deadline) ? Status::Cancelled("stop") : Status::Ok();
  };
  if (std::optional<InferenceResult> failed = RunDetector(
          *result.model->detector, *image, options, cancellation, boundaries, result.detection)) {
    return std::move(*failed);
  }
  result.timings.insert(result.timings.end(), result.detection.timings.begin(),
                        result.detection.timings.end());
  // The last boundary: a caller that gave up during the final stage gets no OK either.
  if (const std::optional<CancelReason> reason = StopReason(cancellation, request.deadline)) {
    return Stopped(*reason, "after the pipeline ran");
  }

  if (request.encode_map_png && !result.detection.probability.empty()) {
    const Clock::time_point encode_start = Clock::now();
    Result<std::string> png = EncodeProbabilityPng(result.detection.probability);
    if (!png.ok()) return Refusal(png.status(), Rejection::kInternal);
    result.map_png = std::move(*png);
    result.timings.emplace_back("encode_map", MillisecondsSince(encode_start));
  }
  if (observer_ != nullptr) {
    observer_->OnDetected(result.model->name(), result.timings, result.detection);
    observer_->OnCameras(cameras_.size());
  }
  return result;
}

bool InferenceEngine::Ready() const {
  std::lock_guard lock(mutex_);
  return !draining_ && !stopping_ && !models_.empty();
}

void InferenceEngine::BeginDrain() {
  std::lock_guard lock(mutex_);
  draining_ = true;
}

bool InferenceEngine::draining() const {
  std::lock_guard lock(mutex_);
  return draining_ || stopping_;
}

size_t InferenceEngine::queue_depth() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

bool InferenceEngine::WaitIdle(Clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return idle_.wait_until(lock, deadline, [this] { return queue_.empty() && running_ == 0; });
}

void InferenceEngine::CancelAll(CancelReason reason) {
  std::deque<Job> queued;
  {
    std::lock_guard lock(mutex_);
    draining_ = true;
    queued.swap(queue_);
    for (const std::shared_ptr<Cancellation>& running : running_cancellations_) {
      running->Cancel(reason);
    }
    if (observer_ != nullptr) observer_->OnQueueDepth(0);
  }
  for (Job& job : queued) {
    job.cancellation->Cancel(reason);
    if (observer_ != nullptr) observer_->OnFinished();
    Finish(job.done, Stopped(*job.cancellation->reason(), "while the request was queued"),
           job.submitted);
  }
  idle_.notify_all();
}

void InferenceEngine::Stop() {
  std::vector<std::thread> workers;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    workers.swap(workers_);
  }
  work_available_.notify_all();
  for (std::thread& worker : workers) worker.join();
  // With no workers left (never started, or all joined), answer whatever is still queued.
  std::deque<Job> leftover;
  {
    std::lock_guard lock(mutex_);
    leftover.swap(queue_);
  }
  for (Job& job : leftover) {
    if (observer_ != nullptr) observer_->OnFinished();
    Finish(job.done,
           Refusal(Status::Unavailable("server shut down before the request ran"),
                   Rejection::kNotReady),
           job.submitted);
  }
}

}  // namespace tod::server
