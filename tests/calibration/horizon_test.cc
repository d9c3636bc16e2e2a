#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "core/calibration/camera_registry.h"
#include "core/calibration/horizon_choice.h"
#include "core/calibration/horizon_estimator.h"
#include "core/calibration/horizon_reference.h"
#include "core/synth/synth.h"

namespace tod {
namespace {

// Synthetic cameras of other heights, pitches (horizon rows) and lenses: the true horizon is
// known, and the estimate must land within 10 rows at 1024.
TEST(HorizonEstimatorTest, FindsTheSyntheticCamerasHorizon) {
  struct Camera {
    double horizon_frac, height_m, focal_frac;
  };
  int within = 0, total = 0;
  for (const Camera& c : {Camera{0.40, 1.4, 1.1}, Camera{0.28, 2.0, 0.8}, Camera{0.52, 1.1, 1.4}}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      SynthParams params;
      params.width = 1024;
      params.height = 512;
      params.horizon_frac = c.horizon_frac;
      params.camera_height_m = c.height_m;
      params.focal_frac = c.focal_frac;
      const SynthFrame frame = GenerateSynthFrameDetailed(params, seed, "f");
      const HorizonEstimate est = EstimateHorizon(frame.sample.image);
      ++total;
      if (est.found && std::abs(est.row - frame.camera.horizon_row) * 1024.0 / 512 <= 10) ++within;
    }
  }
  EXPECT_GE(within, total - 1) << within << " of " << total << " within 10 rows";
}

TEST(HorizonEstimatorTest, AFrameWithoutLinesHasNoEstimate) {
  const cv::Mat3b flat(256, 512, cv::Vec3b(90, 90, 90));
  const HorizonEstimate est = EstimateHorizon(flat);
  EXPECT_FALSE(est.found);
  EXPECT_FALSE(est.reason.empty());
}

TEST(HorizonChoiceTest, CameraThenFrameThenBundle) {
  HorizonEstimate frame;
  frame.found = true;
  frame.row = 500;
  frame.peak_pairs = 100;
  // No reference: the bundle's geometry, said why.
  HorizonUse use = ChooseHorizon(std::nullopt, 1024, frame, nullptr);
  EXPECT_EQ(use.source, HorizonSource::kBundle);
  EXPECT_FALSE(use.fallback.empty());
  EXPECT_EQ(use.shift, 0);
  // The frame's estimate, 100 rows below the reference: moved by 100.
  use = ChooseHorizon(400.0, 1024, frame, nullptr);
  EXPECT_EQ(use.source, HorizonSource::kFrame);
  EXPECT_DOUBLE_EQ(use.shift, 100);
  // Within the deadband: not moved.
  frame.row = 410;
  EXPECT_EQ(ChooseHorizon(400.0, 1024, frame, nullptr).shift, 0);
  // A lone frame 40 rows off is within its own wider deadband; a camera's median is not.
  frame.row = 440;
  EXPECT_EQ(ChooseHorizon(400.0, 1024, frame, nullptr).shift, 0);
  {
    CameraTrack steady;
    EXPECT_DOUBLE_EQ(ChooseHorizon(400.0, 1024, frame, &steady).shift, 40);
  }
  // A lone frame's estimate from too few agreeing pairs moves nothing, and says why.
  frame.row = 500;
  frame.peak_pairs = 20;
  use = ChooseHorizon(400.0, 1024, frame, nullptr);
  EXPECT_EQ(use.source, HorizonSource::kBundle);
  EXPECT_EQ(use.shift, 0);
  EXPECT_NE(use.fallback.find("pairs"), std::string::npos) << use.fallback;
  frame.peak_pairs = 100;
  // A camera: the median of its frames, counted.
  CameraTrack camera;
  for (double row : {600.0, 600.0, 100.0}) {
    frame.row = row;
    use = ChooseHorizon(400.0, 1024, frame, &camera);
  }
  EXPECT_EQ(use.source, HorizonSource::kCamera);
  EXPECT_EQ(use.camera_frames, 3);
  EXPECT_DOUBLE_EQ(*use.row, 600);
  // No estimate on this frame: the camera's still stands.
  frame.found = false;
  use = ChooseHorizon(400.0, 1024, frame, &camera);
  EXPECT_EQ(use.source, HorizonSource::kCamera);
  EXPECT_DOUBLE_EQ(use.shift, 200);
  // The camera's frames rescaled to half the height: its estimate scales with them.
  use = ChooseHorizon(200.0, 512, frame, &camera);
  EXPECT_DOUBLE_EQ(*use.row, 300);
  EXPECT_DOUBLE_EQ(use.shift, 100);
}

TEST(CameraHorizonTest, MedianOverTheLastWindow) {
  CameraHorizon h;
  EXPECT_FALSE(h.Estimate().has_value());
  for (int i = 0; i < 200; ++i) h.Add(i < 100 ? 0.0 : 50.0);
  EXPECT_DOUBLE_EQ(*h.Estimate(), 50.0);  // the first 100 fell out of the window
  EXPECT_EQ(h.frames(), 200);
}

TEST(CameraRegistryTest, BoundedAndForgetsIdleCameras) {
  CameraRegistry registry({.max_cameras = 3, .idle_seconds = 60});
  const auto t0 = CameraRegistry::Clock::time_point{} + std::chrono::hours(1);
  auto a = registry.Track("a", t0);
  EXPECT_EQ(a, registry.Track("a", t0));  // one track per camera
  registry.Track("b", t0 + std::chrono::seconds(1));
  registry.Track("c", t0 + std::chrono::seconds(2));
  registry.Track("d", t0 + std::chrono::seconds(3));  // full: the least recently seen goes
  EXPECT_EQ(registry.size(), 3u);
  EXPECT_NE(a, registry.Track("a", t0 + std::chrono::seconds(4)));  // "a" was forgotten
  registry.Track("e", t0 + std::chrono::seconds(200));              // all others idle
  EXPECT_EQ(registry.size(), 1u);
  EXPECT_GE(registry.forgotten(), 4);
}

TEST(HorizonReferenceTest, MedianAndSpreadRoundTrip) {
  std::vector<HorizonEstimate> estimates(7);
  const double rows[] = {400, 402, 398, 401, 700, 0, 399};
  for (int i = 0; i < 7; ++i) {
    estimates[i].found = i != 5;
    estimates[i].row = rows[i];
  }
  auto ref = ReferenceFromEstimates(estimates, 1024);
  ASSERT_TRUE(ref.ok());
  EXPECT_DOUBLE_EQ(ref->row, 400.5);
  EXPECT_EQ(ref->frames, 6);
  auto back = HorizonReference::FromJson(ref->ToJson());
  ASSERT_TRUE(back.ok());
  EXPECT_DOUBLE_EQ(back->row, ref->row);
  EXPECT_FALSE(ReferenceFromEstimates({estimates[0]}, 1024).ok());
}

}  // namespace
}  // namespace tod
