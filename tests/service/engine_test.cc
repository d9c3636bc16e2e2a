// The engine's admission control, queue, deadlines, draining and model snapshots, driven step by
// step through a gated test detector (no network, no real model).
#include <gtest/gtest.h>

#include <future>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "server/core/inference_engine.h"
#include "server/metrics.h"
#include "tests/service/fake_detectors.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

using testing::GatedDetector;

// Collects one engine completion.
struct Outcome {
  std::promise<InferenceResult> promise;
  std::future<InferenceResult> future = promise.get_future();
  Completion callback() {
    return [this](InferenceResult result) { promise.set_value(std::move(result)); };
  }
  InferenceResult get() { return future.get(); }
  bool ready() { return future.wait_for(std::chrono::seconds(0)) == std::future_status::ready; }
};

class EngineTest : public ::testing::Test {
 protected:
  void SetUpEngine(int workers, int queue, bool gate_open) {
    detector_ = std::make_shared<GatedDetector>("v1", gate_open);
    models_.Install(detector_, "/models/one");
    EngineConfig config;
    config.workers = workers;
    config.queue_capacity = queue;
    config.limits.max_bytes = 200'000;
    config.limits.max_pixels = 400 * 200;
    engine_ = std::make_unique<InferenceEngine>(config, models_, &metrics_);
    engine_->Start();
  }
  InferenceRequest Request() {
    InferenceRequest request;
    request.image = image_;
    return request;
  }

  const std::string image_ = testing::RoadPng();
  std::shared_ptr<GatedDetector> detector_;
  ModelHolder models_;
  ServerMetrics metrics_;
  std::unique_ptr<InferenceEngine> engine_;
};

TEST_F(EngineTest, RunsDetectionAndEncodesTheMap) {
  SetUpEngine(1, 4, /*gate_open=*/true);
  Outcome outcome;
  engine_->Submit(Request(), outcome.callback());
  const InferenceResult result = outcome.get();
  ASSERT_TRUE(result.status.ok()) << result.status.ToString();
  EXPECT_EQ(result.detection.width, 320);
  EXPECT_EQ(result.detection.height, 160);
  ASSERT_EQ(result.detection.obstacles.size(), 1u);
  EXPECT_EQ(result.detection.obstacles[0].box, (Box{150, 110, 12, 10}));
  // P = 0.25 everywhere -> round(0.25 * 255) = 64 in the PNG.
  const std::vector<uchar> png(result.map_png.begin(), result.map_png.end());
  const cv::Mat map = cv::imdecode(png, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(map.type(), CV_8UC1);
  EXPECT_EQ(map.size(), cv::Size(320, 160));
  EXPECT_EQ(map.at<uchar>(80, 100), 64);
  // Timings: queue, decode, the pipeline's own stages, encode_map, in that order.
  ASSERT_EQ(result.timings.size(), 4u);
  EXPECT_EQ(result.timings[0].first, "queue");
  EXPECT_EQ(result.timings[1].first, "decode");
  EXPECT_EQ(result.timings[2].first, "fake_stage");
  EXPECT_EQ(result.timings[3].first, "encode_map");
  EXPECT_EQ(result.model->generation, 1);
}

TEST_F(EngineTest, NoMapWhenNotRequested) {
  SetUpEngine(1, 4, true);
  InferenceRequest request = Request();
  request.encode_map_png = false;
  Outcome outcome;
  engine_->Submit(request, outcome.callback());
  const InferenceResult result = outcome.get();
  ASSERT_TRUE(result.status.ok());
  EXPECT_TRUE(result.map_png.empty());
  EXPECT_TRUE(result.detection.probability.empty());
}

TEST_F(EngineTest, RefusesBadInputBeforeQueueing) {
  SetUpEngine(1, 4, true);
  struct Case {
    std::string image;
    DetectOptions options;
    Rejection expected;
    StatusCode code;
  };
  DetectOptions bad_threshold;
  bad_threshold.obstacle_threshold = 1.5f;
  DetectOptions bad_count;
  bad_count.max_proposals = -1;
  const std::vector<Case> cases = {
      {"", {}, Rejection::kBadImage, StatusCode::kInvalidArgument},
      {"definitely not an image", {}, Rejection::kBadImage, StatusCode::kInvalidArgument},
      {std::string(200'001, 'x'), {}, Rejection::kTooLarge, StatusCode::kResourceExhausted},
      // 401 x 200 > 400 * 200 pixels: refused from the header, never decoded.
      {testing::RoadPng(401, 200), {}, Rejection::kTooLarge, StatusCode::kResourceExhausted},
      {image_, bad_threshold, Rejection::kBadRequest, StatusCode::kInvalidArgument},
      {image_, bad_count, Rejection::kBadRequest, StatusCode::kInvalidArgument},
  };
  for (const Case& c : cases) {
    InferenceRequest request;
    request.image = c.image;
    request.options = c.options;
    Outcome outcome;
    engine_->Submit(request, outcome.callback());
    ASSERT_TRUE(outcome.ready()) << "refusals are answered inline";
    const InferenceResult result = outcome.get();
    EXPECT_EQ(result.rejection, c.expected) << result.status.message();
    EXPECT_EQ(result.status.code(), c.code) << result.status.message();
    EXPECT_FALSE(result.status.message().empty());
  }
  EXPECT_EQ(detector_->started(), 0);
  EXPECT_NE(metrics_.SerializeText().find("tod_rejections_total{reason=\"too_large\"} 2"),
            std::string::npos);
}

TEST_F(EngineTest, CorruptBodyWithValidHeaderIsInvalidArgument) {
  SetUpEngine(1, 4, true);
  const std::string truncated = image_.substr(0, 40);  // PNG header intact, data cut off
  InferenceRequest request;
  request.image = truncated;
  Outcome outcome;
  engine_->Submit(request, outcome.callback());
  const InferenceResult result = outcome.get();
  EXPECT_EQ(result.status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(result.rejection, Rejection::kBadImage);
  EXPECT_EQ(detector_->started(), 0);
}

TEST_F(EngineTest, FullQueueIsRefusedAtOnce) {
  SetUpEngine(/*workers=*/1, /*queue=*/1, /*gate_open=*/false);
  Outcome running, queued, refused;
  engine_->Submit(Request(), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  engine_->Submit(Request(), queued.callback());
  EXPECT_EQ(engine_->queue_depth(), 1u);
  engine_->Submit(Request(), refused.callback());
  ASSERT_TRUE(refused.ready());
  const InferenceResult refusal = refused.get();
  EXPECT_EQ(refusal.rejection, Rejection::kQueueFull);
  EXPECT_EQ(refusal.status.code(), StatusCode::kResourceExhausted);
  detector_->Open();
  EXPECT_TRUE(running.get().status.ok());
  EXPECT_TRUE(queued.get().status.ok());
  EXPECT_EQ(detector_->started(), 2);
}

TEST_F(EngineTest, DeadlinePassedInQueueSkipsTheWork) {
  SetUpEngine(1, 2, false);
  Outcome running, late;
  engine_->Submit(Request(), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  InferenceRequest request = Request();
  request.deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(5);
  engine_->Submit(request, late.callback());
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  detector_->Open();
  EXPECT_TRUE(running.get().status.ok());
  const InferenceResult result = late.get();
  EXPECT_EQ(result.status.code(), StatusCode::kDeadlineExceeded);
  EXPECT_EQ(result.rejection, Rejection::kDeadline);
  EXPECT_TRUE(engine_->WaitIdle(std::chrono::steady_clock::now() + std::chrono::seconds(5)));
  EXPECT_EQ(detector_->started(), 1) << "the expired request must not run";
}

TEST_F(EngineTest, DrainRefusesNewWorkAndFinishesAdmittedWork) {
  SetUpEngine(1, 4, false);
  Outcome first, second, after_drain;
  engine_->Submit(Request(), first.callback());
  engine_->Submit(Request(), second.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  EXPECT_TRUE(engine_->Ready());
  engine_->BeginDrain();
  EXPECT_FALSE(engine_->Ready());
  engine_->Submit(Request(), after_drain.callback());
  EXPECT_EQ(after_drain.get().status.code(), StatusCode::kUnavailable);
  EXPECT_FALSE(engine_->WaitIdle(std::chrono::steady_clock::now() + std::chrono::milliseconds(20)));
  detector_->Open();
  EXPECT_TRUE(engine_->WaitIdle(std::chrono::steady_clock::now() + std::chrono::seconds(5)));
  EXPECT_TRUE(first.get().status.ok());
  EXPECT_TRUE(second.get().status.ok());
}

TEST_F(EngineTest, StopAnswersQueuedRequestsWithUnavailable) {
  SetUpEngine(1, 4, false);
  Outcome running, queued;
  engine_->Submit(Request(), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  engine_->Submit(Request(), queued.callback());
  std::thread stopper([this] { engine_->Stop(); });
  // The gate opens only once Stop() has marked the engine stopping (it is then not ready): had
  // it opened first, the worker could take the queued request before Stop() began.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (engine_->Ready() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(engine_->Ready());
  detector_->Open();
  stopper.join();
  EXPECT_TRUE(running.get().status.ok());
  EXPECT_EQ(queued.get().status.code(), StatusCode::kUnavailable);
  EXPECT_EQ(detector_->started(), 1);
}

TEST_F(EngineTest, RequestKeepsTheModelItStartedWith) {
  SetUpEngine(1, 4, false);
  Outcome old_model;
  engine_->Submit(Request(), old_model.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  models_.Install(std::make_shared<GatedDetector>("v2"), "/models/two");  // reload mid-request
  detector_->Open();
  const InferenceResult first = old_model.get();
  ASSERT_TRUE(first.status.ok());
  EXPECT_EQ(first.model->generation, 1);
  EXPECT_EQ(first.model->detector->info().version, "v1");
  Outcome new_model;
  engine_->Submit(Request(), new_model.callback());
  const InferenceResult second = new_model.get();
  ASSERT_TRUE(second.status.ok());
  EXPECT_EQ(second.model->generation, 2);
  EXPECT_EQ(second.model->detector->info().version, "v2");
}

TEST(EngineWithoutModel, IsNotReady) {
  ModelHolder models;
  InferenceEngine engine(EngineConfig{}, models, nullptr);
  engine.Start();
  EXPECT_FALSE(engine.Ready());
  const std::string image = testing::RoadPng();
  InferenceRequest request;
  request.image = image;
  std::promise<InferenceResult> promise;
  engine.Submit(request, [&](InferenceResult result) { promise.set_value(std::move(result)); });
  const InferenceResult result = promise.get_future().get();
  EXPECT_EQ(result.status.code(), StatusCode::kUnavailable);
  EXPECT_EQ(result.rejection, Rejection::kNotReady);
}

TEST(ModelHolderTest, FailedLoadKeepsTheCurrentModel) {
  ModelHolder models;
  models.Install(std::make_shared<testing::GatedDetector>("v1"), "/nonexistent/bundle");
  const Status reload = models.Reload().status();  // the directory does not exist
  EXPECT_FALSE(reload.ok());
  EXPECT_NE(reload.message().find("/nonexistent/bundle"), std::string::npos) << reload.message();
  ASSERT_NE(models.Current(), nullptr);
  EXPECT_EQ(models.Current()->generation, 1);
  EXPECT_EQ(models.Current()->detector->info().version, "v1");
}

}  // namespace
}  // namespace tod::server

namespace tod::server {
namespace {

using testing::GatedDetector;

class EngineCancellationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    detector_ = std::make_shared<GatedDetector>("v1", /*open=*/false);
    models_.Install(detector_, "/models/one");
    EngineConfig config;
    config.workers = 1;
    config.queue_capacity = 4;
    engine_ = std::make_unique<InferenceEngine>(config, models_, &metrics_);
    engine_->Start();
  }
  InferenceRequest Request(std::shared_ptr<Cancellation> cancellation = nullptr) {
    InferenceRequest request;
    request.image = image_;
    request.cancellation = std::move(cancellation);
    return request;
  }
  double Cancelled(const std::string& reason) {
    const std::string text = metrics_.SerializeText();
    const std::string series = "tod_requests_cancelled_total{reason=\"" + reason + "\"} ";
    const size_t at = text.find(series);
    return at == std::string::npos ? -1 : std::stod(text.substr(at + series.size()));
  }
  struct Waiter {
    std::promise<InferenceResult> promise;
    std::future<InferenceResult> future = promise.get_future();
    Completion callback() {
      return [this](InferenceResult result) { promise.set_value(std::move(result)); };
    }
  };

  const std::string image_ = testing::RoadPng();
  std::shared_ptr<GatedDetector> detector_;
  ModelHolder models_;
  ServerMetrics metrics_;
  std::unique_ptr<InferenceEngine> engine_;
};

TEST_F(EngineCancellationTest, RunningRequestStopsAtTheNextStageBoundary) {
  auto cancellation = std::make_shared<Cancellation>();
  Waiter running;
  engine_->Submit(Request(cancellation), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  cancellation->Cancel(CancelReason::kClientCancelled);
  detector_->Open();  // the fake's one stage ends; its boundary sees the cancellation
  const InferenceResult result = running.future.get();
  EXPECT_EQ(result.status.code(), StatusCode::kCancelled) << result.status.ToString();
  EXPECT_EQ(result.rejection, Rejection::kCancelled);
  ASSERT_TRUE(result.cancelled.has_value());
  EXPECT_EQ(*result.cancelled, CancelReason::kClientCancelled);
  EXPECT_EQ(Cancelled("client_cancelled"), 1);
  EXPECT_EQ(Cancelled("drain"), 0);
}

TEST_F(EngineCancellationTest, QueuedRequestOfAGoneClientIsSkipped) {
  Waiter running, queued;
  engine_->Submit(Request(), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  auto cancellation = std::make_shared<Cancellation>();
  engine_->Submit(Request(cancellation), queued.callback());
  cancellation->Cancel(CancelReason::kClientDisconnected);
  detector_->Open();
  EXPECT_TRUE(running.future.get().status.ok());
  const InferenceResult skipped = queued.future.get();
  EXPECT_EQ(skipped.status.code(), StatusCode::kCancelled);
  EXPECT_EQ(detector_->started(), 1) << "the gone client's request must not run";
  EXPECT_EQ(Cancelled("client_disconnected"), 1);
}

TEST_F(EngineCancellationTest, CancelAllAnswersQueuedAtOnceAndStopsRunning) {
  Waiter running, queued1, queued2;
  engine_->Submit(Request(), running.callback());
  ASSERT_TRUE(detector_->WaitStarted(1));
  engine_->Submit(Request(), queued1.callback());
  engine_->Submit(Request(), queued2.callback());
  engine_->BeginDrain();
  engine_->CancelAll(CancelReason::kDrain);
  // Queued ones are answered before the running one ends.
  for (Waiter* queued : {&queued1, &queued2}) {
    ASSERT_EQ(queued->future.wait_for(std::chrono::seconds(0)), std::future_status::ready);
    const InferenceResult result = queued->future.get();
    EXPECT_EQ(result.status.code(), StatusCode::kUnavailable);
    EXPECT_EQ(result.cancelled, CancelReason::kDrain);
  }
  EXPECT_EQ(engine_->queue_depth(), 0u);
  detector_->Open();
  const InferenceResult stopped = running.future.get();
  EXPECT_EQ(stopped.status.code(), StatusCode::kUnavailable) << stopped.status.ToString();
  EXPECT_TRUE(engine_->WaitIdle(std::chrono::steady_clock::now() + std::chrono::seconds(60)));
  EXPECT_EQ(Cancelled("drain"), 3);
  EXPECT_EQ(detector_->started(), 1);
}

TEST_F(EngineCancellationTest, DeadlinePassingWhileRunningStopsTheWork) {
  InferenceRequest request = Request();
  request.deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(1);
  Waiter running;
  // Submitted while the gate is closed: the worker takes it at once (before the deadline, most
  // likely) or after (then it is skipped); either way it ends DEADLINE_EXCEEDED, never OK.
  engine_->Submit(request, running.callback());
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  detector_->Open();
  const InferenceResult result = running.future.get();
  EXPECT_EQ(result.status.code(), StatusCode::kDeadlineExceeded);
  EXPECT_EQ(result.rejection, Rejection::kDeadline);
  EXPECT_EQ(Cancelled("deadline"), 1);
}

}  // namespace
}  // namespace tod::server
