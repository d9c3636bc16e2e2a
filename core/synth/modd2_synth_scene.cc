// GenerateModd2SynthFrame: one synthetic marine scene and its annotation (modd2_synth.h).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/modd2/modd2_ground_truth.h"
#include "core/synth/modd2_synth.h"

namespace tod {
namespace {

constexpr int kMinObjectSide = 7;  // (7 - 1) * (7 - 1) = 36 >= the 25 px threshold

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }
  int Int(int lo, int hi) {
    return std::uniform_int_distribution<int>(lo, std::max(lo, hi))(engine_);
  }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }

 private:
  std::mt19937_64 engine_;
};

std::uint64_t Mix(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

struct Horizon {
  double base = 0;   // 1-based y at the image centre
  double slope = 0;  // px per px
  double amplitude = 0;
  double period = 0;
  double phase = 0;
  double width = 0;
  double At(double x) const {
    return base + slope * (x - width / 2) +
           amplitude * std::sin(2 * std::numbers::pi * x / period + phase);
  }
};

// 1-based [x y w h] whose filter_obstacles.m rounding gives exactly `pixels` (0-based, half-open),
// with a fractional jitter below half a pixel as in hand-made annotations.
cv::Rect2d AnnotationFor(const Box& pixels, Rng& rng) {
  return {pixels.x + 1 + rng.Uniform(-0.3, 0.3), pixels.y + 1 + rng.Uniform(-0.3, 0.3),
          pixels.w - 1 + rng.Uniform(-0.3, 0.3), pixels.h - 1 + rng.Uniform(-0.3, 0.3)};
}

bool OverlapsAny(const Box& b, const std::vector<Box>& others, int margin) {
  const Box grown{b.x - margin, b.y - margin, b.w + 2 * margin, b.h + 2 * margin};
  return std::any_of(others.begin(), others.end(),
                     [&](const Box& o) { return !Intersect(grown, o).empty(); });
}

void PaintSkyAndWater(const cv::Mat1b& water, const Horizon& horizon, Rng& rng, cv::Mat3b* image) {
  const double wave_phase = rng.Uniform(0, 2 * std::numbers::pi);
  const double tint = rng.Uniform(-15, 15);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::mt19937_64 noise_engine(static_cast<std::uint64_t>(rng.Int(0, 1 << 30)));
  for (int r = 0; r < image->rows; ++r) {
    for (int c = 0; c < image->cols; ++c) {
      const double edge_row = horizon.At(c + 1) - 1;  // 0-based
      const double n = noise(noise_engine);
      cv::Vec3d bgr;
      if (water(r, c)) {
        // Waves get longer and stronger towards the camera (rows further below the horizon).
        const double d = std::max(0.0, r - edge_row);
        const double wave = std::sin(c / (3.0 + 0.35 * d) + 0.9 * d + wave_phase) *
                            std::sin(0.45 * d + 0.5 * wave_phase);
        const double shade = (10 + 0.2 * d) * wave + 4 * n;
        bgr = {115 + tint + shade, 95 + shade + 0.1 * d, 45 + 0.5 * shade};
      } else {
        // Sky: deeper blue at the top, hazy near the horizon.
        const double t = std::clamp(r / std::max(1.0, edge_row), 0.0, 1.0);
        bgr = {235 + 5 * t + 2 * n, 200 + 25 * t + 2 * n, 140 + 60 * t + 2 * n};
      }
      for (int k = 0; k < 3; ++k) (*image)(r, c)[k] = cv::saturate_cast<unsigned char>(bgr[k]);
    }
  }
}

void PaintLargeObstacle(const Box& b, Rng& rng, cv::Mat3b* image) {
  const double gray = rng.Uniform(50, 120);
  (*image)(b.rect()).setTo(cv::Scalar(gray, gray, gray + 10));
  // A lighter superstructure band and dark windows, so the object has inner edges.
  const int band = std::max(1, b.h / 3);
  (*image)(cv::Rect(b.x, b.y, b.w, band)).setTo(cv::Scalar(gray + 80, gray + 80, gray + 70));
  for (int x = b.x + 2; x + 2 < b.right(); x += 5) {
    cv::rectangle(*image, cv::Rect(x, b.y + band / 3, 2, std::max(1, band / 3)),
                  cv::Scalar(30, 30, 30), cv::FILLED);
  }
}

void PaintFloatingObject(const Box& b, Rng& rng, cv::Mat3b* image) {
  static const cv::Scalar kColours[] = {
      {30, 40, 220}, {20, 140, 250}, {40, 220, 240}, {235, 235, 235}, {40, 200, 60}};
  const cv::Scalar colour = kColours[rng.Int(0, 4)];
  const cv::Point2f centre(b.x + (b.w - 1) / 2.0f, b.y + (b.h - 1) / 2.0f);
  cv::ellipse(*image, cv::RotatedRect(centre, cv::Size2f(b.w - 1.0f, b.h - 1.0f), 0), colour,
              cv::FILLED, cv::LINE_8);
  // Shaded lower half.
  const cv::Rect lower(b.x, b.y + b.h / 2, b.w, b.h - b.h / 2);
  cv::Mat3b part = (*image)(lower);
  cv::Mat3b shaded;
  part.convertTo(shaded, -1, 0.75, 0);
  const cv::Mat1b inside = cv::Mat1b::zeros(lower.size());
  cv::ellipse(
      inside,
      cv::RotatedRect(centre - cv::Point2f(lower.tl()), cv::Size2f(b.w - 1.0f, b.h - 1.0f), 0),
      cv::Scalar(255), cv::FILLED, cv::LINE_8);
  shaded.copyTo(part, inside);
}

}  // namespace

std::uint64_t Modd2SynthFrameSeed(std::uint64_t dataset_seed, int sequence_index, int frame_index) {
  return Mix(Mix(Mix(dataset_seed) ^ static_cast<std::uint64_t>(sequence_index)) ^
             static_cast<std::uint64_t>(frame_index));
}

namespace {

Horizon RandomHorizon(int width, int height, Rng& rng) {
  Horizon horizon;
  horizon.width = width;
  horizon.base = rng.Uniform(0.33, 0.45) * height;
  horizon.slope = rng.Uniform(-0.03, 0.03) * height / width;
  horizon.amplitude = rng.Uniform(0.3, 1.5);
  horizon.period = rng.Uniform(0.3, 0.8) * width;
  horizon.phase = rng.Uniform(0, 2 * std::numbers::pi);
  return horizon;
}

// Sea edge, left to right, 1-based, into the annotation. Like the real annotations, the end
// points may lie a little outside the image and a NaN row may appear; the reader cleans both.
// Returns the largest 1-based y of the edge.
double AnnotateSeaEdge(const Horizon& horizon, int width, Rng& rng, Modd2Annotation& annotation) {
  const int points = 16;
  double lowest_edge = 0;
  for (int k = 0; k < points; ++k) {
    double x = 1 + (width - 1) * static_cast<double>(k) / (points - 1);
    if (k == 0 && rng.Chance(0.5)) x -= rng.Uniform(0.1, 1.5);
    if (k == points - 1 && rng.Chance(0.5)) x += rng.Uniform(0.1, 1.5);
    const double y = horizon.At(std::clamp(x, 1.0, static_cast<double>(width)));
    annotation.sea_edge.emplace_back(x, y);
    lowest_edge = std::max(lowest_edge, y);
    if (k == points / 2 && rng.Chance(0.3)) {
      annotation.sea_edge.emplace_back(std::nan(""), std::nan(""));
    }
  }
  return lowest_edge;
}

// Large obstacles straddle the horizon: their top is well above the sea edge. None, one or two,
// apart from each other.
std::vector<Box> PlaceLargeObstacles(const Horizon& horizon, int width, int height, Rng& rng) {
  std::vector<Box> placed;
  const int large_count = rng.Chance(0.3) ? 0 : (rng.Chance(0.7) ? 1 : 2);
  for (int i = 0; i < large_count; ++i) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const int w = rng.Int(std::max(6, width / 12), std::max(8, width / 5));
      const int x = rng.Int(2, width - w - 2);
      double edge_top = height;
      double edge_bottom = 0;
      for (int c = x; c < x + w; ++c) {
        edge_top = std::min(edge_top, horizon.At(c + 1) - 1);
        edge_bottom = std::max(edge_bottom, horizon.At(c + 1) - 1);
      }
      const int top =
          std::max(1, static_cast<int>(std::floor(edge_top)) - rng.Int(4, std::max(5, height / 8)));
      const int bottom =
          std::min(height, static_cast<int>(std::ceil(edge_bottom)) + rng.Int(2, 2 + height / 25));
      const Box box{x, top, w, bottom - top};
      if (OverlapsAny(box, placed, 3)) continue;
      placed.push_back(box);
      break;
    }
  }
  return placed;
}

// Small floating objects, entirely on the water below `lowest_edge` (1-based) and apart from
// `large`; nearer (lower) ones may be larger.
std::vector<Box> PlaceSmallObstacles(double lowest_edge, const std::vector<Box>& large, int width,
                                     int height, Rng& rng) {
  const int first_row = static_cast<int>(std::ceil(lowest_edge)) + 3;  // 0-based, below the edge
  const int max_side_w = std::max(kMinObjectSide, std::min(width / 12, 40));
  const int max_side_h = std::max(kMinObjectSide, std::min(height / 10, 30));
  const int small_count = rng.Int(1, 4);
  std::vector<Box> occupied = large;
  std::vector<Box> placed;
  for (int i = 0; i < small_count; ++i) {
    for (int attempt = 0; attempt < 30; ++attempt) {
      const int top = rng.Int(first_row, height - kMinObjectSide);
      const double nearness =
          static_cast<double>(top - first_row) / std::max(1, height - first_row);
      const int w =
          rng.Int(kMinObjectSide,
                  kMinObjectSide + static_cast<int>((max_side_w - kMinObjectSide) * nearness));
      const int h = std::min(
          rng.Int(kMinObjectSide,
                  kMinObjectSide + static_cast<int>((max_side_h - kMinObjectSide) * nearness)),
          height - top);
      const int x = rng.Int(0, width - w);
      const Box box{x, top, w, h};
      if (h < kMinObjectSide || OverlapsAny(box, occupied, 2)) continue;
      occupied.push_back(box);
      placed.push_back(box);
      break;
    }
  }
  return placed;
}

}  // namespace

Modd2SynthFrame GenerateModd2SynthFrame(int width, int height, std::uint64_t seed) {
  width = std::max(width, kModd2SynthMinWidth);
  height = std::max(height, kModd2SynthMinHeight);
  Rng rng(seed);
  Modd2SynthFrame frame;
  const Horizon horizon = RandomHorizon(width, height, rng);
  const double lowest_edge = AnnotateSeaEdge(horizon, width, rng, frame.annotation);
  const std::vector<cv::Point2d> cleaned = CleanSeaEdge(frame.annotation.sea_edge, width, height);
  const cv::Mat1b water = Modd2WaterMask(cleaned, width, height);
  frame.image = cv::Mat3b(height, width);
  PaintSkyAndWater(water, horizon, rng, &frame.image);

  frame.large_obstacles = PlaceLargeObstacles(horizon, width, height, rng);
  for (const Box& b : frame.large_obstacles) PaintLargeObstacle(b, rng, &frame.image);
  frame.small_obstacles =
      PlaceSmallObstacles(lowest_edge, frame.large_obstacles, width, height, rng);
  for (const Box& b : frame.small_obstacles) PaintFloatingObject(b, rng, &frame.image);

  // Annotation rows: small objects first (their order is small_obstacles' order), then large.
  for (const Box& b : frame.small_obstacles) {
    frame.annotation.obstacles.push_back(AnnotationFor(b, rng));
  }
  for (const Box& b : frame.large_obstacles) {
    frame.annotation.obstacles.push_back(AnnotationFor(b, rng));
  }
  return frame;
}

}  // namespace tod
