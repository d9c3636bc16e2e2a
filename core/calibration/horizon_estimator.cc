#include "core/calibration/horizon_estimator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace tod {
namespace {

struct Segment {
  cv::Point2d a, b;  // working-frame pixels
  double length = 0;
  double angle = 0;  // radians, direction of a -> b in [0, pi)
  double y_min = 0, y_max = 0;
};

// The frame in grey at the working width.
cv::Mat1b WorkingGrey(const cv::Mat3b& bgr, int working_width, double* scale) {
  cv::Mat1b grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  *scale = 1.0;
  if (bgr.cols <= working_width) return grey;
  *scale = static_cast<double>(working_width) / bgr.cols;
  cv::Mat1b small;
  cv::resize(grey, small, cv::Size(), *scale, *scale, cv::INTER_AREA);
  return small;
}

// LSD's segments that can point at a vanishing point: long enough, oblique; the longest first.
std::vector<Segment> ObliqueSegments(const cv::Mat1b& grey, const HorizonParams& p) {
  std::vector<cv::Vec4f> lines;
  cv::createLineSegmentDetector(cv::LSD_REFINE_STD)->detect(grey, lines);
  const double min_length = p.min_length_frac * grey.cols;
  const double deg = std::numbers::pi / 180.0;
  std::vector<Segment> out;
  for (const cv::Vec4f& l : lines) {
    Segment s{{l[0], l[1]}, {l[2], l[3]}};
    const cv::Point2d d = s.b - s.a;
    s.length = std::hypot(d.x, d.y);
    if (s.length < min_length) continue;
    double angle = std::atan2(d.y, d.x);
    if (angle < 0) angle += std::numbers::pi;
    if (angle >= std::numbers::pi) angle -= std::numbers::pi;
    const double from_horizontal = std::min(angle, std::numbers::pi - angle);
    if (from_horizontal < p.min_angle_deg * deg || from_horizontal > p.max_angle_deg * deg)
      continue;
    s.angle = angle;
    s.y_min = std::min(s.a.y, s.b.y);
    s.y_max = std::max(s.a.y, s.b.y);
    out.push_back(s);
  }
  std::sort(out.begin(), out.end(),
            [](const Segment& x, const Segment& y) { return x.length > y.length; });
  if (static_cast<int>(out.size()) > p.max_segments) out.resize(p.max_segments);
  return out;
}

// The row where the lines through s and t meet, if they meet beyond both segments' rows.
bool MeetingRow(const Segment& s, const Segment& t, double* row) {
  const cv::Point2d r = s.b - s.a, q = t.b - t.a;
  const double cross = r.x * q.y - r.y * q.x;
  if (std::abs(cross) < 1e-9) return false;
  const cv::Point2d w = t.a - s.a;
  const double u = (w.x * q.y - w.y * q.x) / cross;
  const double y = s.a.y + u * r.y;
  // A vanishing point lies beyond the segments pointing at it, not on them: lines that cross
  // inside a segment are two things touching (a marking across a kerb), not parallels.
  const double margin = 2.0;
  if (y > s.y_min - margin && y < s.y_max + margin) return false;
  if (y > t.y_min - margin && y < t.y_max + margin) return false;
  *row = y;
  return true;
}

}  // namespace

HorizonEstimate EstimateHorizon(const cv::Mat3b& bgr, const HorizonParams& p) {
  HorizonEstimate est;
  if (bgr.empty()) {
    est.reason = "empty frame";
    return est;
  }
  double scale = 1.0;
  const cv::Mat1b grey = WorkingGrey(bgr, p.working_width, &scale);
  const std::vector<Segment> segments = ObliqueSegments(grey, p);
  est.segments = static_cast<int>(segments.size());
  // Votes on rows [top, bottom) of the working frame, one bin a pixel.
  const int top = static_cast<int>(std::floor(-p.search_above_frac * grey.rows));
  const int bottom = static_cast<int>(std::ceil(p.search_below_frac * grey.rows));
  const int bins = bottom - top;
  std::vector<double> votes(bins, 0.0);
  std::vector<int> pair_rows(bins, 0);
  const int reach = static_cast<int>(std::ceil(3 * p.vote_sigma_px));
  const double inv_two_sigma2 = 1.0 / (2 * p.vote_sigma_px * p.vote_sigma_px);
  double total = 0;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    for (std::size_t j = i + 1; j < segments.size(); ++j) {
      double row = 0;
      if (!MeetingRow(segments[i], segments[j], &row)) continue;
      if (row < top || row >= bottom) continue;
      const double weight = segments[i].length * segments[j].length *
                            std::abs(std::sin(segments[i].angle - segments[j].angle));
      total += weight;
      const int centre = static_cast<int>(std::floor(row)) - top;
      ++pair_rows[centre];
      for (int b = std::max(0, centre - reach); b <= std::min(bins - 1, centre + reach); ++b) {
        const double d = b + 0.5 - (row - top);
        votes[b] += weight * std::exp(-d * d * inv_two_sigma2);
      }
    }
  }
  if (total <= 0) {
    est.reason = "no pair of oblique line segments meets in the searched rows";
    return est;
  }
  const int peak = static_cast<int>(std::max_element(votes.begin(), votes.end()) - votes.begin());
  // The peak's row to a fraction of a bin: the votes' centroid around it.
  double mass = 0, moment = 0;
  int pairs = 0;
  for (int b = std::max(0, peak - reach); b <= std::min(bins - 1, peak + reach); ++b) {
    mass += votes[b];
    moment += votes[b] * (b + 0.5);
    pairs += pair_rows[b];
  }
  // The Gaussian's mass is sqrt(2 pi) sigma a vote: the share of all votes at the peak.
  est.peak_share = mass / (total * std::sqrt(2 * std::numbers::pi) * p.vote_sigma_px);
  est.peak_pairs = pairs;
  est.row = (top + moment / mass) / scale;
  if (est.peak_share < p.min_peak_share || pairs < p.min_pairs) {
    est.reason = "the line segments agree on no row (peak share " +
                 std::to_string(est.peak_share).substr(0, 5) + ", " + std::to_string(pairs) +
                 " pairs)";
    return est;
  }
  est.found = true;
  return est;
}

}  // namespace tod
