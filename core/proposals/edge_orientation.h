// Per-pixel edge orientation of an OLP edge map (ALGORITHM.md §4.1): the same recipe Edge Boxes
// uses, so that edge grouping (§4.2.1) sees orientations of the form it was tuned for.
#pragma once

#include <opencv2/core.hpp>

namespace tod {

// Smooths the map with a radius-4 triangle filter (1,2,3,4,5,4,3,2,1)/25 (reflect padding), takes
// central-difference gradients (one-sided at the borders) and second derivatives
// Oxx = d/dx(Ox), Oxy = d/dx(Oy), Oyy = d/dy(Oy), and returns
//   theta = mod(atan(Oyy * sign(-Oxy) / (Oxx + 1e-5)), pi)   in [0, pi).
// Empty input gives an empty result.
cv::Mat1f ComputeEdgeOrientation(const cv::Mat1f& edge_map);
// The same, but theta only where edge_map > min_magnitude (0 elsewhere): edge grouping reads
// orientations of edge pixels only, and the per-pixel arctangent is the costly part.
cv::Mat1f ComputeEdgeOrientation(const cv::Mat1f& edge_map, float min_magnitude);

// The two halves of ComputeEdgeOrientation for callers that need theta at a few pixels only
// (edge grouping reads it at edge pixels, a few % of a map): the smoothed map, and theta at one
// pixel of it from its 5x5 neighbourhood. OrientationAt(SmoothForOrientation(m), r, c) is
// bit-identical to ComputeEdgeOrientation(m)(r, c): it evaluates the same float expressions of
// the same smoothed values, border rules included, without the five full derivative maps.
cv::Mat1f SmoothForOrientation(const cv::Mat1f& edge_map);
float OrientationAt(const cv::Mat1f& smoothed, int r, int c);

// Central differences in the interior, one-sided differences on the first / last column (row);
// a single column (row) has zero derivative. Exposed for tests.
cv::Mat1f DerivativeX(const cv::Mat1f& map);
cv::Mat1f DerivativeY(const cv::Mat1f& map);

}  // namespace tod
