// The fast label-map routines of the sticky superpixels against straightforward references:
// run-based connected-component labelling against a per-pixel flood fill, and the refinement
// (row border flags, dense renumbering) against the plain per-candidate cost loop, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "core/edges/superpixel_boundaries.h"
#include "core/edges/superpixel_refine.h"

namespace tod {
namespace {

// 4-connected components numbered 1.. in raster order of first appearance (flood fill).
cv::Mat1i ReferenceComponents(const cv::Mat1i& labels, int* count) {
  cv::Mat1i out(labels.size(), 0);
  *count = 0;
  std::vector<cv::Point> stack;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (out(y, x) != 0) continue;
      out(y, x) = ++*count;
      stack.push_back({x, y});
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        for (const cv::Point d :
             {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
          const cv::Point q = p + d;
          if (q.x < 0 || q.y < 0 || q.x >= labels.cols || q.y >= labels.rows) continue;
          if (out(q) != 0 || labels(q) != labels(p)) continue;
          out(q) = *count;
          stack.push_back(q);
        }
      }
    }
  }
  return out;
}

// Random map of a few labels painted as rectangles, diagonal staircases and single pixels:
// many components, U shapes that merge late, and diagonal-only contacts.
cv::Mat1i RandomLabels(int width, int height, int num_labels, cv::RNG& rng) {
  cv::Mat1i labels(height, width, 0);
  for (int s = 0; s < 3 * (width + height); ++s) {
    const int label = rng.uniform(0, num_labels);
    const int shape = rng.uniform(0, 3);
    const int x0 = rng.uniform(0, width);
    const int y0 = rng.uniform(0, height);
    if (shape == 0) {
      const int x1 = std::min(width, x0 + rng.uniform(1, 8));
      const int y1 = std::min(height, y0 + rng.uniform(1, 8));
      labels(cv::Range(y0, y1), cv::Range(x0, x1)).setTo(label);
    } else if (shape == 1) {
      for (int k = 0; k < 6 && x0 + k < width && y0 + k < height; ++k) {
        labels(y0 + k, x0 + k) = label;  // touches itself only diagonally
      }
    } else {
      labels(y0, x0) = label;
    }
  }
  return labels;
}

TEST(RelabelConnectedComponentsTest, MatchesFloodFillOnRandomMaps) {
  cv::RNG rng(7);
  const std::vector<cv::Size> sizes = {{1, 1},  {1, 17}, {23, 1},  {2, 2},
                                       {5, 40}, {37, 3}, {64, 48}, {129, 77}};
  for (const cv::Size size : sizes) {
    for (int trial = 0; trial < 20; ++trial) {
      const int num_labels = 1 + trial % 4;  // 1 label: one component; more: many
      cv::Mat1i labels = RandomLabels(size.width, size.height, num_labels, rng);
      int expected_count = 0;
      const cv::Mat1i expected = ReferenceComponents(labels, &expected_count);
      const int count = RelabelConnectedComponents(labels);
      ASSERT_EQ(count, expected_count) << size << " trial " << trial;
      ASSERT_EQ(cv::countNonZero(labels != expected), 0) << size << " trial " << trial;
    }
  }
}

TEST(RelabelConnectedComponentsTest, DiagonalContactDoesNotConnect) {
  cv::Mat1i labels = (cv::Mat1i(3, 3) << 5, 0, 5, 0, 5, 0, 5, 0, 5);
  // The 5s and the 0s alike touch their kind only diagonally: nine components.
  EXPECT_EQ(RelabelConnectedComponents(labels), 9);
  const cv::Mat1i expected = (cv::Mat1i(3, 3) << 1, 2, 3, 4, 5, 6, 7, 8, 9);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0);
}

// The refinement as first written: every distinct neighbouring label evaluated in turn.
int ReferenceRefine(const StickyImage& image, const StickyWeights& weights, int iterations,
                    std::vector<int>& labels) {
  struct Sums {
    double count = 0, x = 0, y = 0, c0 = 0, c1 = 0, c2 = 0, inverse_count = 0;
    void Add(double sign, int px, int py, const float* c) {
      count += sign;
      inverse_count = count > 0 ? 1.0 / count : 0.0;
      x += sign * px;
      y += sign * py;
      c0 += sign * c[0];
      c1 += sign * c[1];
      c2 += sign * c[2];
    }
  };
  const int width = image.width;
  const int height = image.height;
  std::vector<Sums> sums(*std::max_element(labels.begin(), labels.end()) + 1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      sums[labels[i]].Add(1.0, x, y, image.colour + 3 * i);
    }
  int sweeps = 0;
  for (int iter = 0; iter < iterations; ++iter) {
    ++sweeps;
    long long moved = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        const int own = labels[i];
        std::vector<size_t> nb;
        if (x > 0) nb.push_back(i - 1);
        if (y > 0) nb.push_back(i - width);
        if (x + 1 < width) nb.push_back(i + 1);
        if (y + 1 < height) nb.push_back(i + width);
        bool on_border = false;
        for (const size_t j : nb) on_border |= labels[j] != own;
        if (!on_border) continue;
        const float* c = image.colour + 3 * i;
        auto cost = [&](int t) {
          const Sums& s = sums[t];
          const double n = s.count + (t == own ? 0.0 : 1.0);
          const double inv = s.inverse_count;
          const double dx = x - s.x * inv;
          const double dy = y - s.y * inv;
          const double d0 = c[0] - s.c0 * inv;
          const double d1 = c[1] - s.c1 * inv;
          const double d2 = c[2] - s.c2 * inv;
          float e_min = std::numeric_limits<float>::max();
          float e_max = 0.f;
          for (const size_t j : nb) {
            e_max = std::max(e_max, image.edge[j]);
            if (labels[j] != t) e_min = std::min(e_min, image.edge[j]);
          }
          const double e_t = e_min == std::numeric_limits<float>::max() ? e_max : e_min;
          return weights.position * (dx * dx + dy * dy) +
                 weights.colour * (d0 * d0 + d1 * d1 + d2 * d2) - weights.edge * e_t +
                 weights.size / n;
        };
        int best = own;
        double best_cost = cost(own);
        std::vector<int> seen = {own};
        for (const size_t j : nb) {
          const int t = labels[j];
          if (std::find(seen.begin(), seen.end(), t) != seen.end()) continue;
          seen.push_back(t);
          const double ct = cost(t);
          if (ct < best_cost) {
            best_cost = ct;
            best = t;
          }
        }
        if (best != own) {
          sums[own].Add(-1.0, x, y, c);
          sums[best].Add(1.0, x, y, c);
          labels[i] = best;
          ++moved;
        }
      }
    }
    if (moved == 0) break;
  }
  return sweeps;
}

TEST(RefineStickyLabelsTest, MatchesPlainCostLoopBitForBit) {
  cv::RNG rng(11);
  const std::vector<cv::Size> sizes = {{1, 9}, {9, 1}, {2, 3}, {31, 17}, {80, 45}};
  for (const cv::Size size : sizes) {
    for (int trial = 0; trial < 4; ++trial) {
      const size_t n = static_cast<size_t>(size.area());
      std::vector<float> colour(3 * n);
      std::vector<float> edge(n);
      // Smooth blobs plus noise, a few exact ties in the edge map (whole numbers / 4).
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
          const size_t i = static_cast<size_t>(y) * size.width + x;
          for (int k = 0; k < 3; ++k) {
            colour[3 * i + k] =
                static_cast<float>(((x / 7 + y / 5 + k) % 3) * 0.3 + rng.uniform(0.0, 0.05));
          }
          edge[i] = trial % 2 == 0 ? static_cast<float>(rng.uniform(0, 5)) / 4.f
                                   : static_cast<float>(rng.uniform(0.0, 2.0));
        }
      const StickyImage image{size.width, size.height, colour.data(), edge.data()};
      StickyWeights weights = StickyWeightsFor(64, 0.5, 0.9);
      weights.position *= 4.0 * (1 + trial);
      // One label per pixel (shuffled ids, as at half resolution) or blocks (as at full).
      std::vector<int> labels(n);
      for (size_t i = 0; i < n; ++i) {
        const int x = static_cast<int>(i % size.width);
        const int y = static_cast<int>(i / size.width);
        labels[i] = trial < 2 ? static_cast<int>(n - 1 - i) : 3 * ((y / 4) * 64 + x / 4) + 7;
      }
      std::vector<int> expected = labels;
      const int expected_sweeps = ReferenceRefine(image, weights, 8, expected);
      const int sweeps = RefineStickyLabels(image, weights, 8, labels);
      EXPECT_EQ(sweeps, expected_sweeps) << size << " trial " << trial;
      EXPECT_EQ(labels, expected) << size << " trial " << trial;
    }
  }
}

}  // namespace
}  // namespace tod
