// The geometry that turns a MODDv2 annotation (sea-edge polyline, 1-based fractional boxes) into
// pixel masks, reproducing the official evaluation code (bborja/modd: filter_sea_edge.m,
// filter_obstacles.m, build_gt_segmentation_mask and gtObjectsSegm in evaluate_detections_modd2.m;
// see /work/shared/docs/MODD2-FORMAT.md). Exposed so tests can check each rule on its own.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/base/types.h"

namespace tod {

// MATLAB poly2mask semantics: a pixel belongs to the polygon when its centre is inside it. The
// polygon is given in MATLAB 1-based coordinates (pixel (row r, column c) has its centre at
// x = c, y = r). A centre lying exactly on the boundary follows poly2mask's documented behaviour
// (the [4 10 10 4] square covers columns and rows 5..10): it is inside when the polygon lies on
// its left / upper side, i.e. the point is tested as if nudged infinitesimally up and left.
// Even-odd rule; the polygon closes itself. Returns height x width, 255 inside.
// Not reproduced: poly2mask first snaps vertices to a 1/5-pixel grid, so the two can differ on
// pixels whose centre lies within 0.2 px of a slanted edge.
cv::Mat1b FillPolygonPixelCentres(const std::vector<cv::Point2d>& polygon, int width, int height);

// filter_sea_edge.m: drops points with a non-finite coordinate, clamps x to [1, width] and y to at
// most height (y is not clamped from below, as in the official code).
std::vector<cv::Point2d> CleanSeaEdge(const std::vector<cv::Point2d>& sea_edge, int width,
                                      int height);

// build_gt_segmentation_mask: water = the area below the cleaned sea edge. Points with a
// coordinate < 0 or > width are dropped, the first point's x becomes 0.5 and the last one's
// width + 0.5, and the polygon is closed along the bottom row (y = height). No usable point gives
// an empty mask (the official code would stop with an error there).
cv::Mat1b Modd2WaterMask(const std::vector<cv::Point2d>& cleaned_sea_edge, int width, int height);

// The "inverse sea mask" of perform_evaluation_on_sequence.m: the polygon (1,1), the cleaned sea
// edge, (width,1); a box touching it is a large obstacle.
cv::Mat1b Modd2AboveSeaEdgeMask(const std::vector<cv::Point2d>& cleaned_sea_edge, int width,
                                int height);

// One annotated box after filter_obstacles.m: x, y, w, h are rounded (half away from zero), x and y
// clamped into [1, width] x [1, height], w and h capped at width - x and height - y. The box then
// covers the inclusive 1-based pixel range [x, x + w] x [y, y + h], i.e. w + 1 columns: `pixels`
// is that range as a 0-based half-open Box (empty when a rounded w or h is negative).
// `official_area` = w * h, the size gtObjectsSegm compares with the 25 px threshold.
struct Modd2PixelBox {
  Box pixels;
  long long official_area = 0;
  bool valid = false;  // false for non-finite input or negative rounded extents
};
Modd2PixelBox RoundModd2Box(const cv::Rect2d& stored_box, int width, int height);

// Freezone with eval_params.freezone = 0 (evaluate_detections_modd2.m): in each column, the rows
// from the top down to the last one before the water mask first changes value (row 0 alone when it
// never changes). A small obstacle with a corner in it is removed from the ground truth.
cv::Mat1b Modd2Freezone(const cv::Mat1b& water);

}  // namespace tod
