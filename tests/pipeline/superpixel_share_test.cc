// SuperpixelShare counts a box's superpixels once and looks their weights up; the reference here
// recounts them for every pixel, as the definition reads, on random superpixel maps and boxes.
#include "core/pipeline/superpixel_share.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace tod {
namespace {

// Labels of the nearest of `seeds` random points (a Voronoi map), with 0 wherever a pixel's
// right or lower neighbour has another label (1-pixel boundaries), and a few out-of-range labels.
Superpixels RandomSuperpixels(int width, int height, int seeds, std::mt19937& rng) {
  std::uniform_int_distribution<int> px(0, width - 1), py(0, height - 1);
  std::vector<cv::Point> points(seeds);
  for (auto& p : points) p = {px(rng), py(rng)};
  cv::Mat1i nearest(height, width);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int best = 0;
      for (int s = 1; s < seeds; ++s)
        if (cv::norm(points[s] - cv::Point(x, y)) < cv::norm(points[best] - cv::Point(x, y)))
          best = s;
      nearest(y, x) = best + 1;
    }
  Superpixels sp;
  sp.count = seeds;
  sp.labels = nearest.clone();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if ((x + 1 < width && nearest(y, x + 1) != nearest(y, x)) ||
          (y + 1 < height && nearest(y + 1, x) != nearest(y, x)))
        sp.labels(y, x) = 0;
  sp.labels(0, 0) = seeds + 7;  // out of range: treated as a boundary
  return sp;
}

// How a painted value meets the map's: kept if larger (PaintMax) or added (PaintAdd).
enum class Combine { kMax, kAdd };

// The definition, pixel by pixel.
void ReferencePaint(const Superpixels& sp, const Box& crop, const Box& box, float value,
                    Combine combine, cv::Mat1f* map) {
  const Box b = ClipToImage(box, map->cols, map->rows);
  auto label_at = [&](int x, int y) {  // frame coordinates; -1 outside the crop
    const int cx = x - crop.x, cy = y - crop.y;
    if (cx < 0 || cy < 0 || cx >= sp.labels.cols || cy >= sp.labels.rows) return -1;
    const int l = sp.labels(cy, cx);
    return l > 0 && l <= sp.count ? l : 0;
  };
  auto weight_of = [&](int label) {
    long long inside = 0, area = 0;
    for (int y = 0; y < sp.labels.rows; ++y)
      for (int x = 0; x < sp.labels.cols; ++x) {
        if (label_at(x + crop.x, y + crop.y) != label) continue;
        ++area;
        inside += b.rect().contains({x + crop.x, y + crop.y});
      }
    return value * static_cast<float>(inside) / static_cast<float>(area);
  };
  for (int y = b.y; y < b.bottom(); ++y)
    for (int x = b.x; x < b.right(); ++x) {
      const int label = label_at(x, y);
      float v = value;
      if (label > 0) {
        v = weight_of(label);
      } else if (label == 0) {
        v = 0.f;
        const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int n = label_at(x + dx[k], y + dy[k]);
          if (n > 0) v = std::max(v, weight_of(n));
        }
      }
      (*map)(y, x) = combine == Combine::kMax ? std::max((*map)(y, x), v) : (*map)(y, x) + v;
    }
}

// Random boxes, some partly or wholly off the crop and the frame, painted one after the other.
void ExpectTheDefinition(Combine combine) {
  std::mt19937 rng(7);
  const cv::Size frame(90, 60);
  const Box crop{12, 9, 60, 40};
  const Superpixels sp = RandomSuperpixels(crop.w, crop.h, 25, rng);
  std::uniform_int_distribution<int> x(-10, frame.width), y(-10, frame.height), side(1, 50);
  std::uniform_real_distribution<float> value(0.f, 1.f);
  cv::Mat1f fast(frame, 0.f), reference(frame, 0.f);
  SuperpixelShare share(sp, crop);
  for (int i = 0; i < 200; ++i) {
    const Box box{x(rng), y(rng), side(rng), side(rng)};
    const float v = value(rng);
    if (combine == Combine::kMax) {
      share.PaintMax(box, v, &fast);
    } else {
      share.PaintAdd(box, v, &fast);
    }
    ReferencePaint(sp, crop, box, v, combine, &reference);
    // A touched superpixel neighbouring a boundary pixel outside this box must not leak its
    // weight into the next box: compare after every box.
    ASSERT_EQ(cv::countNonZero(fast != reference), 0) << "box " << i;
  }
}

TEST(SuperpixelShareTest, EqualsThePixelByPixelDefinition) { ExpectTheDefinition(Combine::kMax); }

TEST(SuperpixelShareTest, AddsThePixelByPixelDefinition) { ExpectTheDefinition(Combine::kAdd); }

}  // namespace
}  // namespace tod
