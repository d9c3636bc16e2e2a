#include "core/proposals/edge_box_scorer.h"

#include <cmath>
#include <string>

#include "core/proposals/box_scorer.h"
#include "core/proposals/window_scan.h"

namespace tod {
namespace {

// Larger maps would overflow the int pixel indexes of the scorer; regions are <= 2048 wide.
constexpr int kMaxMapSide = 32767;

Status OutOfRange(const std::string& field, const std::string& range, double value) {
  return Status::InvalidArgument("EdgeBoxParams." + field + " must be " + range + ", got " +
                                 std::to_string(value));
}

bool Usable(const cv::Mat1f& map) {
  return !map.empty() && map.cols <= kMaxMapSide && map.rows <= kMaxMapSide;
}

}  // namespace

Status ValidateEdgeBoxParams(const EdgeBoxParams& p) {
  // Written as !(x in range) so that NaN is rejected too.
  if (!(p.alpha > 0.f && p.alpha < 1.f)) return OutOfRange("alpha", "in (0, 1)", p.alpha);
  if (!(p.beta >= 0.f && p.beta <= 1.f)) return OutOfRange("beta", "in [0, 1]", p.beta);
  if (!(p.min_score > 0.f)) return OutOfRange("min_score", "> 0", p.min_score);
  if (p.max_boxes < 0) return OutOfRange("max_boxes", ">= 0", p.max_boxes);
  if (!(p.edge_min_mag >= 0.f)) return OutOfRange("edge_min_mag", ">= 0", p.edge_min_mag);
  if (!(p.edge_merge_thr > 0.f)) return OutOfRange("edge_merge_thr", "> 0", p.edge_merge_thr);
  if (!(p.cluster_min_mag >= 0.f)) {
    return OutOfRange("cluster_min_mag", ">= 0", p.cluster_min_mag);
  }
  if (!(p.max_aspect_ratio >= 1.f && p.max_aspect_ratio <= 1000.f)) {
    return OutOfRange("max_aspect_ratio", "in [1, 1000]", p.max_aspect_ratio);
  }
  if (!(p.max_wide_aspect_ratio == 0.f ||
        (p.max_wide_aspect_ratio >= 1.f && p.max_wide_aspect_ratio <= 1000.f))) {
    return OutOfRange("max_wide_aspect_ratio", "0 or in [1, 1000]", p.max_wide_aspect_ratio);
  }
  if (!(p.min_box_area >= 1.f)) return OutOfRange("min_box_area", ">= 1", p.min_box_area);
  if (!(p.gamma >= 0.f && std::isfinite(p.gamma))) return OutOfRange("gamma", ">= 0", p.gamma);
  if (!(p.kappa > 0.f && std::isfinite(p.kappa))) return OutOfRange("kappa", "> 0", p.kappa);
  if (!(p.stride_factor > 0.f && p.stride_factor <= 1.f)) {
    return OutOfRange("stride_factor", "in (0, 1]", p.stride_factor);
  }
  if (p.min_stride < 1) return OutOfRange("min_stride", ">= 1", p.min_stride);
  if (p.refine_limit < 0)
    return OutOfRange("refine_limit", ">= 0 (0 = refine all)", p.refine_limit);
  if (p.threads < 0) return OutOfRange("threads", ">= 0 (0 = all cores)", p.threads);
  return Status::Ok();
}

std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params) {
  return ScoreEdgeBoxes(edge_map, params, nullptr);
}

std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params,
                                      EdgeBoxStats* stats) {
  return ScoreEdgeBoxes(edge_map, params, stats, nullptr);
}

std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params,
                                      EdgeBoxStats* stats, const WindowAdmission* admission) {
  EdgeBoxStats local;
  EdgeBoxStats& s = stats != nullptr ? *stats : local;
  s = EdgeBoxStats{};
  if (!Usable(edge_map) || !ValidateEdgeBoxParams(params).ok()) return {};

  const BoxScorer scorer(edge_map, params);
  s.edge_pixels = static_cast<long long>(scorer.groups().edges.row_col.size());
  s.edge_groups = scorer.groups().count();
  std::vector<ScoredBox> kept = ScanWindowGrid(scorer, params, s, admission);
  s.boxes_out = static_cast<long long>(kept.size());
  return kept;
}

float ScoreSingleBox(const cv::Mat1f& edge_map, const Box& box, const EdgeBoxParams& params) {
  if (!Usable(edge_map) || box.empty() || !ValidateEdgeBoxParams(params).ok()) return 0.f;
  const Box clipped = ClipToImage(box, edge_map.cols, edge_map.rows);
  if (clipped.empty()) return 0.f;
  BoxScorer scorer(edge_map, params);
  ScoreWindow w{clipped.y, clipped.x, clipped.bottom() - 1, clipped.right() - 1, 0.f};
  scorer.Score(w);
  return w.score;
}

float MaxFiniteValue(const cv::Mat1f& map) {
  float max_value = 0.f;
  for (int r = 0; r < map.rows; ++r) {
    const float* row = map[r];
    for (int c = 0; c < map.cols; ++c) {
      if (row[c] > max_value && std::isfinite(row[c])) max_value = row[c];  // NaN/inf ignored
    }
  }
  return max_value;
}

cv::Mat1f NormaliseToMax(const cv::Mat1f& map) {
  const float max_value = MaxFiniteValue(map);
  if (max_value <= 0.f) return map.clone();
  cv::Mat1f out;
  map.convertTo(out, CV_32F, 1.0 / max_value);
  return out;
}

}  // namespace tod
