// The engine's reports through EngineObserver, recorded in order: what it says for a detection,
// a refusal at admission, a full queue and the drain; and how ServerMetrics counts the same
// events (the engine itself knows nothing of Prometheus).
#include "server/core/engine_observer.h"

#include <gtest/gtest.h>

#include <future>
#include <mutex>
#include <string>
#include <vector>

#include "server/core/inference_engine.h"
#include "server/metrics.h"
#include "tests/service/fake_detectors.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

// Every report as one line ("accepted 1", "rejected queue_full", ...), in the order it came.
class RecordingObserver final : public EngineObserver {
 public:
  void OnAccepted(size_t depth) override { Add("accepted " + std::to_string(depth)); }
  void OnQueueDepth(size_t depth) override { Add("queue " + std::to_string(depth)); }
  void OnStarted(double) override { Add("started"); }
  void OnFinished() override { Add("finished"); }
  void OnRejected(Rejection rejection) override {
    Add(std::string("rejected ") + RejectionName(rejection));
  }
  void OnCancelled(CancelReason reason) override {
    Add(std::string("cancelled ") + CancelReasonName(reason));
  }
  void OnDetected(const std::string& model, const StageTimes& timings,
                  const Detection& detection) override {
    std::string line = "detected " + model;
    for (const auto& [stage, ms] : timings) line += " " + stage;
    for (const std::string& stage : detection.degraded_stages) line += " degraded:" + stage;
    line += std::string(" geometry:") + HorizonSourceName(detection.horizon.source);
    Add(line);
  }
  void OnCameras(size_t cameras) override { Add("cameras " + std::to_string(cameras)); }

  std::vector<std::string> events() const {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  void Add(std::string event) {
    std::lock_guard lock(mutex_);
    events_.push_back(std::move(event));
  }
  mutable std::mutex mutex_;
  std::vector<std::string> events_;
};

// The gated test detector, with the frame budget cutting its regression short.
class DegradedDetector final : public testing::GatedDetector {
 public:
  DegradedDetector() : GatedDetector("v1") {}
  Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options) const override {
    Result<Detection> detection = GatedDetector::Detect(bgr, options);
    if (detection.ok()) detection->degraded_stages = {"regression"};
    return detection;
  }
};

class EngineObserverTest : public ::testing::Test {
 protected:
  void SetUpEngine(std::shared_ptr<const Detector> detector, int queue_capacity = 4) {
    models_.Install(std::move(detector), "/models/one");
    EngineConfig config;
    config.workers = 1;
    config.queue_capacity = queue_capacity;
    engine_ = std::make_unique<InferenceEngine>(config, models_, &observer_);
    engine_->Start();
  }
  // Submits the test frame with `options` (of camera `camera_id`, or of the stream whose track
  // is `stream_camera`); the future has the result.
  std::future<InferenceResult> Submit(const DetectOptions& options = {},
                                      const std::string& camera_id = "",
                                      std::shared_ptr<CameraTrack> stream_camera = nullptr) {
    auto promise = std::make_shared<std::promise<InferenceResult>>();
    std::future<InferenceResult> future = promise->get_future();
    InferenceRequest request;
    request.image = image_;
    request.options = options;
    request.camera_id = camera_id;
    request.stream_camera = std::move(stream_camera);
    engine_->Submit(request,
                    [promise](InferenceResult result) { promise->set_value(std::move(result)); });
    return future;
  }

  const std::string image_ = testing::RoadPng();
  RecordingObserver observer_;
  ModelHolder models_;
  std::unique_ptr<InferenceEngine> engine_;
};

using Events = std::vector<std::string>;

TEST_F(EngineObserverTest, ReportsADetectionFromAdmissionToAnswer) {
  SetUpEngine(std::make_shared<DegradedDetector>());
  ASSERT_TRUE(Submit().get().status.ok());
  EXPECT_EQ(observer_.events(),
            (Events{"accepted 1", "queue 0", "started",
                    "detected gated queue decode fake_stage encode_map degraded:regression "
                    "geometry:bundle",
                    "cameras 0", "finished"}));
}

TEST_F(EngineObserverTest, ReportsARefusalAtAdmissionAsARejectionOnly) {
  SetUpEngine(std::make_shared<testing::GatedDetector>("v1"));
  DetectOptions too_many;
  too_many.max_proposals = kMaxRequestProposals + 1;
  EXPECT_EQ(Submit(too_many).get().rejection, Rejection::kBadRequest);
  EXPECT_EQ(observer_.events(), (Events{"rejected bad_request"}));
}

// Frames naming a camera share its track in the engine's registry; a stream's own track is used
// when they name none; a camera_id that is too long or not printable is refused at admission.
TEST_F(EngineObserverTest, KeepsOneTrackPerCameraAndRefusesBadCameraIds) {
  SetUpEngine(std::make_shared<testing::GatedDetector>("v1"));
  EXPECT_EQ(Submit({}, "cam-a").get().detection.horizon.camera_frames, 1);
  EXPECT_EQ(Submit({}, "cam-a").get().detection.horizon.camera_frames, 2);
  EXPECT_EQ(Submit({}, "cam-b").get().detection.horizon.camera_frames, 1);
  EXPECT_EQ(engine_->cameras_tracked(), 2u);
  auto stream = std::make_shared<CameraTrack>();
  EXPECT_EQ(Submit({}, "", stream).get().detection.horizon.camera_frames, 1);
  EXPECT_EQ(Submit({}, "", stream).get().detection.horizon.camera_frames, 2);
  EXPECT_EQ(Submit({}, "cam-a", stream).get().detection.horizon.camera_frames, 3);  // named
  EXPECT_EQ(engine_->cameras_tracked(), 2u);  // a stream's track is not in the registry
  const InferenceResult alone = Submit().get();
  EXPECT_EQ(alone.detection.horizon.source, HorizonSource::kBundle);
  EXPECT_EQ(alone.detection.horizon.camera_frames, 0);

  for (const std::string& bad : {std::string(129, 'c'), std::string("cam a"),
                                 std::string("cam\x01"), std::string("cam\xc3\xa9")}) {
    const InferenceResult refused = Submit({}, bad).get();
    EXPECT_EQ(refused.rejection, Rejection::kBadRequest) << bad;
    EXPECT_NE(refused.status.message().find("camera_id"), std::string::npos);
  }
  EXPECT_EQ(Submit({}, std::string(128, 'c')).get().status.ok(), true);
  EXPECT_EQ(engine_->cameras_tracked(), 3u);
}

TEST_F(EngineObserverTest, ReportsAFullQueueAndTheDrainOfQueuedWork) {
  auto detector = std::make_shared<testing::GatedDetector>("v1", /*open=*/false);
  SetUpEngine(detector, /*queue_capacity=*/1);
  std::future<InferenceResult> running = Submit();
  ASSERT_TRUE(detector->WaitStarted(1));
  std::future<InferenceResult> queued = Submit();
  EXPECT_EQ(Submit().get().rejection, Rejection::kQueueFull);
  engine_->CancelAll(CancelReason::kDrain);
  EXPECT_EQ(queued.get().rejection, Rejection::kCancelled);
  detector->Open();
  EXPECT_EQ(running.get().rejection, Rejection::kCancelled);  // stopped at its stage boundary
  EXPECT_EQ(observer_.events(),
            (Events{"accepted 1", "queue 0", "started",                              // running
                    "accepted 1",                                                    // queued
                    "rejected queue_full",                                           // the third
                    "queue 0", "finished", "rejected cancelled", "cancelled drain",  // queued
                    "finished", "rejected cancelled", "cancelled drain"}));          // running
}

TEST_F(EngineObserverTest, StopAnswersQueuedWorkAsFinishedAndNotReady) {
  auto detector = std::make_shared<testing::GatedDetector>("v1", /*open=*/false);
  SetUpEngine(detector);
  std::future<InferenceResult> running = Submit();
  ASSERT_TRUE(detector->WaitStarted(1));
  std::future<InferenceResult> queued = Submit();
  std::thread stopper([this] { engine_->Stop(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  detector->Open();
  stopper.join();
  EXPECT_TRUE(running.get().status.ok());
  EXPECT_EQ(queued.get().rejection, Rejection::kNotReady);
  const Events events = observer_.events();
  // The queued request is answered either by the stopping worker or by Stop() itself; both say
  // it finished, unserved.
  ASSERT_GE(events.size(), 3u);
  EXPECT_EQ(events.back(), "rejected not_ready");
  EXPECT_EQ(events[events.size() - 2], "finished");
}

// The value of one series in the Prometheus text, or -1 when it is absent.
double Series(const ServerMetrics& metrics, const std::string& series) {
  const std::string text = "\n" + metrics.SerializeText();
  const std::string line = "\n" + series + " ";
  const size_t at = text.find(line);
  return at == std::string::npos ? -1 : std::stod(text.substr(at + line.size()));
}

TEST(ServerMetricsAsObserverTest, CountsTheEnginesEvents) {
  ServerMetrics metrics;
  EngineObserver& observer = metrics;
  observer.OnAccepted(3);
  observer.OnAccepted(4);
  EXPECT_EQ(Series(metrics, "tod_queue_depth"), 4);
  EXPECT_EQ(Series(metrics, "tod_in_flight_requests"), 2);
  observer.OnQueueDepth(1);
  observer.OnStarted(250);
  observer.OnFinished();
  EXPECT_EQ(Series(metrics, "tod_queue_depth"), 1);
  EXPECT_EQ(Series(metrics, "tod_in_flight_requests"), 1);
  EXPECT_EQ(Series(metrics, "tod_queue_duration_seconds_sum"), 0.25);
  observer.OnRejected(Rejection::kQueueFull);
  observer.OnCancelled(CancelReason::kClientDisconnected);
  EXPECT_EQ(Series(metrics, "tod_rejections_total{reason=\"queue_full\"}"), 1);
  EXPECT_EQ(Series(metrics, "tod_requests_cancelled_total{reason=\"client_disconnected\"}"), 1);
  EXPECT_EQ(Series(metrics, "tod_requests_cancelled_total{reason=\"drain\"}"), 0);
  Detection detection;
  detection.degraded_stages = {"proposals"};
  detection.horizon.fallback = "no horizon estimate";
  EXPECT_EQ(Series(metrics, "tod_geometry_fallbacks_total"), 0);
  observer.OnDetected("cam7", {{"decode", 500}, {"proposals", 1500}}, detection);
  detection.horizon = HorizonUse{};
  detection.horizon.source = HorizonSource::kCamera;
  detection.horizon.camera_frames = 3;
  observer.OnDetected("cam7", {}, detection);
  observer.OnCameras(4);
  EXPECT_EQ(Series(metrics, "tod_geometry_total{source=\"bundle\"}"), 1);
  EXPECT_EQ(Series(metrics, "tod_geometry_total{source=\"camera\"}"), 1);
  EXPECT_EQ(Series(metrics, "tod_geometry_total{source=\"frame\"}"), 0);
  EXPECT_EQ(Series(metrics, "tod_geometry_fallbacks_total"), 1);
  EXPECT_EQ(Series(metrics, "tod_cameras_tracked"), 4);
  EXPECT_EQ(Series(metrics, "tod_model_frames_total{model=\"cam7\"}"), 2);
  EXPECT_EQ(Series(metrics, "tod_stage_duration_seconds_sum{stage=\"decode\"}"), 0.5);
  EXPECT_EQ(Series(metrics, "tod_stage_duration_seconds_count{stage=\"proposals\"}"), 1);
  EXPECT_EQ(Series(metrics, "tod_frames_degraded_total{stage=\"proposals\"}"), 2);
  EXPECT_EQ(Series(metrics, "tod_frames_degraded_total{stage=\"regression\"}"), 0);
}

}  // namespace
}  // namespace tod::server
