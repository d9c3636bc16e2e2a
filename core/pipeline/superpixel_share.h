// The share of a pixel's superpixel that a box holds: how likely the pixel belongs to the object
// the box frames. The calibrated map (probability_map.h) weights a box's calibrated score by it
// (and the paper's map its fused score, with ProbabilityMapParams::superpixel_shares),
// so the road in a box's corners, whose superpixels run on beyond the box, stays low, while an
// obstacle's superpixels, which the sticky superpixels close along its contour (§3.2), lie
// inside its box and keep the box's score. Not in the paper, whose map paints whole boxes.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/base/types.h"
#include "core/edges/sticky_superpixels.h"

namespace tod {

class SuperpixelShare {
 public:
  // `superpixels` label the crop whose top-left corner is at (crop.x, crop.y) in the frame (R1).
  // Pixels outside the crop have no superpixel: a box holds all of theirs (share 1).
  SuperpixelShare(const Superpixels& superpixels, const Box& crop);

  // map(p) = max(map(p), value * share(p, box)) for every pixel p of `box` (clipped to the map),
  // where share(p, box) = |S(p) ∩ box| / |S(p)| for p's superpixel S(p). A boundary pixel
  // (label 0, on the line between superpixels) takes the largest value of its 4-neighbours'
  // superpixels: it lies on the contour of the object on one of its sides.
  // Cost: two passes over the box's pixels.
  void PaintMax(const Box& box, float value, cv::Mat1f* map);
  // map(p) += value * share(p, box), the same shares (the paper's map with superpixel shares).
  void PaintAdd(const Box& box, float value, cv::Mat1f* map);

 private:
  // The part of `box` on the crop, in crop coordinates: counts the pixels of each superpixel in
  // it and sets weighted_[label] = value * share for every superpixel it touches.
  void WeighSuperpixels(const cv::Rect& on_crop, float value);
  // map(p) = combine(map(p), value * share(p, box)) over the box (PaintMax, PaintAdd).
  template <typename Combine>
  void Paint(const Box& box, float value, cv::Mat1f* map, Combine combine);
  float BoundaryValue(int cx, int cy) const;  // crop coordinates, label 0 there
  void ClearWeights();

  cv::Mat1i labels_;  // 0 = boundary, 1..count; any other value counts as boundary
  Box crop_;
  std::vector<int> area_;            // pixels per label
  std::vector<int> inside_;          // pixels per label in the box being painted
  std::vector<float> weighted_;      // value * share per label for that box (0 if untouched)
  std::vector<int> touched_labels_;  // labels with inside_ > 0, to clear after a box
};

}  // namespace tod
