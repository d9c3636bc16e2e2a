// A tiny untrained bundle and a synthetic road frame for pipeline tests that need every stage to
// run but not to be accurate.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/obstacle_detector.h"
#include "tests/forest/fitted_forest.h"

namespace tod {

// An untrained-edge bundle (gradient edges, the mean-Ê occlusion fallback, the authors' LAF
// regions and size filter) with tiny forests: enough to run every stage on a small frame.
inline ModelBundle TinyBundle() {
  ModelBundle b;
  b.edge_kind = EdgeKind::kGradient;
  b.edges = CreateGradientEdgeSource();
  b.regions = Laf2020Regions();
  b.size_filter = SizeFilter::Laf2020();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  cv::Mat1f x(200, 20);
  std::vector<float> y(200);
  for (int i = 0; i < x.rows; ++i) {
    for (int j = 0; j < 20; ++j) x(i, j) = u(rng);
    y[i] = x(i, 0) > 0.5f ? 1.f : 0.f;
  }
  ForestParams fp;
  fp.num_trees = 3;
  fp.seed = 5;
  b.ordr = FittedForest(x, y, fp);
  b.obdr = FittedForest(x, y, fp);
  b.training = {{"data", "unit test"}};
  return b;
}

// A noisy grey road with dark and bright blocks at several distances (frame rows of the LAF
// regions scaled to the frame).
inline cv::Mat3b RoadFrame(int width, int height) {
  cv::Mat3b frame(height, width, cv::Vec3b(110, 110, 110));
  cv::rectangle(frame, cv::Rect(0, 0, width, height * 37 / 100), cv::Scalar(200, 170, 150),
                cv::FILLED);  // sky
  cv::Mat3b noise(frame.size());
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 12);
  frame += noise;
  const auto block = [&](double x, double y, double w, double h, const cv::Scalar& colour) {
    cv::rectangle(frame,
                  cv::Rect(static_cast<int>(x * width), static_cast<int>(y * height),
                           static_cast<int>(w * width), static_cast<int>(h * height)),
                  colour, cv::FILLED);
  };
  block(0.47, 0.44, 0.02, 0.03, cv::Scalar(30, 30, 40));     // far, inside R4
  block(0.20, 0.62, 0.04, 0.06, cv::Scalar(20, 60, 160));    // middle
  block(0.66, 0.80, 0.06, 0.10, cv::Scalar(230, 230, 230));  // near
  return frame;
}

// The tiny bundle's maps of a 512 x 256 road frame, as the detector computes them.
struct RoadFrameMaps {
  ModelBundle bundle = TinyBundle();
  cv::Mat3b frame = RoadFrame(512, 256);
  FrameGeometry geometry = GeometryForFrame(bundle, frame.cols, frame.rows);
  Result<OcclusionEdges> oaocc = ComputeOcclusionEdges(frame, geometry.regions, *bundle.edges,
                                                       &bundle.occlusion, bundle.params, true);
};

// A suite whose tests share one ObstacleDetector on TinyBundle() (training its forests once).
class TinyDetectorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    detector_ = std::make_unique<const ObstacleDetector>(TinyBundle(), "tiny");
  }
  static void TearDownTestSuite() { detector_.reset(); }
  static inline std::unique_ptr<const ObstacleDetector> detector_;
};

}  // namespace tod
