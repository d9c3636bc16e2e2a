// Proposal feature 21 (ours; docs/method.md#vertical-edge-feature): the share of a box's strong
// intensity gradient that lies on near-vertical edges.
//
// Why: the boxes that outscore the obstacles on real frames are mostly lane stripes and road
// paint, parts of cars, bins and people, and the 20 features of §5 see a stripe differ from the
// road as much as a crate does. An object standing on the road shows its vertical sides as
// vertical edges in the image of an upright road camera; paint lies in the ground plane, where
// perspective turns its edges towards the vanishing point, so it has vertical edges only straight
// ahead. Measured on the dev folds before any training, among each frame's 40 best boxes, this
// share ranks the boxes on obstacles above the false ones (within-frame AUC 0.58–0.78, pooled
// 0.60–0.87 over four models and both folds).
//
// Definition, per pixel p of the greyscale image (OpenCV's BGR → grey), with 3 × 3 Sobel
// derivatives gx, gy and m = hypot(gx, gy): p counts when m >= min_gradient, and it is vertical
// when its edge (perpendicular to the gradient) is within max_tilt_degrees of vertical, i.e.
// |gy| / m < sin(max_tilt_degrees). Over a rectangle, feature 21 = Σ m over vertical pixels /
// Σ m over counted pixels, 0 when no pixel counts. Both sums come from integral images, so a box
// costs four lookups each. The two constants were chosen before anything was measured (a grey
// step of 10 levels, Sobel's 3 × 3 gain being 4, and "about vertical") and were not tuned on the
// dev frames. The camera is taken to be upright (its horizon level), as for any road camera.
//
// Feature 22 (ours, an option measured and not adopted as a regressor feature:
// docs/findings.md#orientation-entropy-feature), with orientation tables: the entropy of the
// orientations of the box's counted pixels. Why: among each frame's 40 best boxes the false ones
// are mostly lane stripes, road paint, kerbs and parts of larger things, whose edges run one or
// two ways (a stripe's two sides, a kerb's line), while a lost object shows its outline, its
// shading and its texture in many directions. Measured on the dev folds with the models of point
// 20 before any training (four models, both folds): within-frame AUC 0.65–0.81, pooled 0.69–0.77,
// where the fused score itself ranks those boxes at 0.38–0.67. Definition: the gradient's
// direction modulo 180° falls in one of kGradientOrientationBins (8) equal bins (bin b centred on
// b · 180° / bins, so the first bin holds the horizontal gradients, i.e. the vertical edges),
// each counted pixel counts 1 in its bin, and feature 22 = −Σ q_b ln q_b / ln 8 over the
// bins' shares q_b of the counted pixels: 0 when every counted pixel has one orientation (or none
// counts), 1 when the orientations are spread evenly. Counts, not magnitudes, so the tables are
// exact 32-bit integers. The eight bins were chosen before the measurement (the usual 20–22.5°
// of orientation histograms), the counting threshold is the vertical share's.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace tod {

struct VerticalEdgeParams {
  double min_gradient = 40.0;      // Sobel magnitude below which a pixel is not an edge
  double max_tilt_degrees = 12.0;  // an edge within this of vertical is vertical
  // Feature 22: build the orientation tables (8 bins: 4 bytes per bin and pixel of the crop).
  bool orientation_tables = false;
};

inline constexpr int kGradientOrientationBins = 8;

class VerticalEdgeIntegrals {
 public:
  // bgr: a colour crop (normally R1, shared by every region of a frame); crop_origin: its
  // top-left corner in the full image. The rows are computed on OpenCV's pool (cv::setNumThreads);
  // the tables are the same for any thread count.
  VerticalEdgeIntegrals(const cv::Mat3b& bgr, cv::Point crop_origin,
                        const VerticalEdgeParams& params = {});

  cv::Size size() const { return size_; }
  cv::Point origin() const { return origin_; }
  // The vertical share of a crop-local rectangle, which must lie inside the crop; 0 when it holds
  // no counted pixel.
  double Share(const cv::Rect& rect) const;
  // The normalised orientation entropy of a crop-local rectangle inside the crop (feature 22, see
  // the top of this file); 0 when it holds no counted pixel. Needs params.orientation_tables.
  double OrientationEntropy(const cv::Rect& rect) const;
  bool has_orientation_tables() const { return !orientation_sum_.empty(); }

 private:
  cv::Size size_;
  cv::Point origin_;
  cv::Mat1d vertical_sum_;  // integral images ((rows + 1) x (cols + 1)) of the two sums
  cv::Mat1d counted_sum_;
  // Integral counts per orientation bin, the bins of one table cell side by side:
  // orientation_sum_[((y * (cols + 1)) + x) * kGradientOrientationBins + b]. Box sums are exact (at
  // most the crop's pixel count).
  std::vector<std::uint32_t> orientation_sum_;
};

}  // namespace tod
