#include "core/modd2/modd2_ground_truth.h"

#include <algorithm>
#include <cmath>

namespace tod {

cv::Mat1b FillPolygonPixelCentres(const std::vector<cv::Point2d>& polygon, int width, int height) {
  cv::Mat1b mask(std::max(height, 0), std::max(width, 0), static_cast<unsigned char>(0));
  const std::size_t n = polygon.size();
  if (n < 3 || width <= 0 || height <= 0) return mask;
  // Crossings of each edge with the rows of pixel centres (1-based row r at y = r), bucketed by
  // row so every edge is visited once.
  std::vector<std::vector<double>> crossings(height + 1);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Point2d& a = polygon[i];
    const cv::Point2d& b = polygon[(i + 1) % n];
    // The centre is tested at y = r - epsilon, so an edge counts for rows in (ymin, ymax];
    // horizontal edges never cross a row.
    const double y_min = std::min(a.y, b.y);
    const double y_max = std::max(a.y, b.y);
    if (!(y_min < y_max) || !std::isfinite(y_min) || !std::isfinite(y_max) || !std::isfinite(a.x) ||
        !std::isfinite(b.x)) {
      continue;
    }
    // Clamped in double before the int conversion, so far-away vertices cannot overflow it.
    const double first = std::clamp(std::floor(y_min) + 1.0, 1.0, height + 1.0);
    const double last = std::clamp(std::floor(y_max), 0.0, static_cast<double>(height));
    for (int r = static_cast<int>(first); r <= last; ++r) {
      crossings[r].push_back(a.x + (r - a.y) * (b.x - a.x) / (b.y - a.y));
    }
  }
  for (int r = 1; r <= height; ++r) {
    std::vector<double>& xs = crossings[r];
    std::sort(xs.begin(), xs.end());
    // Tested at x = c - epsilon: the centre is inside when an odd number of crossings lie
    // strictly left of c, i.e. c in (xs[2k], xs[2k + 1]].
    unsigned char* row = mask.ptr<unsigned char>(r - 1);
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
      const double first_c = std::clamp(std::floor(xs[k]) + 1.0, 1.0, width + 1.0);
      const double last_c = std::clamp(std::floor(xs[k + 1]), 0.0, static_cast<double>(width));
      for (int c = static_cast<int>(first_c); c <= last_c; ++c) row[c - 1] = 255;
    }
  }
  return mask;
}

std::vector<cv::Point2d> CleanSeaEdge(const std::vector<cv::Point2d>& sea_edge, int width,
                                      int height) {
  std::vector<cv::Point2d> cleaned;
  cleaned.reserve(sea_edge.size());
  for (const cv::Point2d& p : sea_edge) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    cleaned.emplace_back(std::clamp(p.x, 1.0, static_cast<double>(width)),
                         std::min(p.y, static_cast<double>(height)));
  }
  return cleaned;
}

cv::Mat1b Modd2WaterMask(const std::vector<cv::Point2d>& cleaned_sea_edge, int width, int height) {
  const double w = width;
  std::vector<cv::Point2d> polygon;
  polygon.reserve(cleaned_sea_edge.size() + 2);
  // build_gt_segmentation_mask drops rows holding any value < 0 or > width (it tests both
  // columns against the image width), then NaN rows (already gone after CleanSeaEdge).
  for (const cv::Point2d& p : cleaned_sea_edge) {
    if (p.x < 0 || p.y < 0 || p.x > w || p.y > w || std::isnan(p.x) || std::isnan(p.y)) continue;
    polygon.push_back(p);
  }
  if (polygon.empty()) {
    return cv::Mat1b(std::max(height, 0), std::max(width, 0), static_cast<unsigned char>(0));
  }
  // Stretch the polyline half a pixel past both image borders so the fill covers every column.
  polygon.front().x = 0.5;
  polygon.back().x = w + 0.5;
  polygon.emplace_back(w + 0.5, height);
  polygon.emplace_back(0.5, height);
  return FillPolygonPixelCentres(polygon, width, height);
}

cv::Mat1b Modd2AboveSeaEdgeMask(const std::vector<cv::Point2d>& cleaned_sea_edge, int width,
                                int height) {
  std::vector<cv::Point2d> polygon;
  polygon.reserve(cleaned_sea_edge.size() + 2);
  polygon.emplace_back(1.0, 1.0);
  polygon.insert(polygon.end(), cleaned_sea_edge.begin(), cleaned_sea_edge.end());
  polygon.emplace_back(static_cast<double>(width), 1.0);
  return FillPolygonPixelCentres(polygon, width, height);
}

Modd2PixelBox RoundModd2Box(const cv::Rect2d& stored_box, int width, int height) {
  Modd2PixelBox result;
  const double values[4] = {stored_box.x, stored_box.y, stored_box.width, stored_box.height};
  for (double v : values) {
    if (!std::isfinite(v)) return result;
  }
  // MATLAB round() rounds half away from zero, as std::round does. Clamping in double first keeps
  // absurd values from overflowing the int conversion.
  const double w_img = width;
  const double h_img = height;
  const double x = std::clamp(std::round(stored_box.x), 1.0, std::max(w_img, 1.0));
  const double y = std::clamp(std::round(stored_box.y), 1.0, std::max(h_img, 1.0));
  const double w = std::clamp(std::round(stored_box.width), -1.0, w_img - x);
  const double h = std::clamp(std::round(stored_box.height), -1.0, h_img - y);
  if (w < 0 || h < 0 || width <= 0 || height <= 0) return result;
  result.valid = true;
  result.official_area = static_cast<long long>(w) * static_cast<long long>(h);
  // Inclusive 1-based [x, x + w] -> 0-based half-open [x - 1, x + w).
  result.pixels = Box{static_cast<int>(x) - 1, static_cast<int>(y) - 1, static_cast<int>(w) + 1,
                      static_cast<int>(h) + 1};
  return result;
}

cv::Mat1b Modd2Freezone(const cv::Mat1b& water) {
  cv::Mat1b freezone(water.size(), static_cast<unsigned char>(0));
  for (int c = 0; c < water.cols; ++c) {
    int last_row = 0;  // no change in the column: the official code takes the first row
    for (int r = 0; r + 1 < water.rows; ++r) {
      if (water(r + 1, c) != water(r, c)) {
        last_row = r;
        break;
      }
    }
    for (int r = 0; r <= last_row && r < water.rows; ++r) freezone(r, c) = 255;
  }
  return freezone;
}

}  // namespace tod
