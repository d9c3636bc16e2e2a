#include "core/evaluation/obstacle_list_sweep.h"

#include <algorithm>
#include <cstdio>

#include "core/pipeline/obstacle_calibration.h"
#include "core/pipeline/obstacle_detector.h"

namespace tod {
namespace {

// "RULE@T/S" and "boxes/S", two decimals each.
std::string RuleKey(const char* rule, float threshold, float min_score) {
  char key[64];
  std::snprintf(key, sizeof key, "%s@%.2f/%.2f", rule, threshold, min_score);
  return key;
}
std::string BoxesKey(float min_score) {
  char key[32];
  std::snprintf(key, sizeof key, "boxes/%.2f", min_score);
  return key;
}

std::vector<Box> BoxesOf(const std::vector<DetectedObstacle>& obstacles) {
  std::vector<Box> out;
  out.reserve(obstacles.size());
  for (const DetectedObstacle& o : obstacles) out.push_back(o.box);
  return out;
}

// Nested or mostly overlapping: the same object twice.
bool SameObject(const Box& a, const Box& b) {
  const long long smaller = std::min(a.area(), b.area());
  return smaller > 0 && 2 * Intersect(a, b).area() > smaller;
}

}  // namespace

ObstacleListCounts& ObstacleListCounts::operator+=(const ObstacleListCounts& o) {
  reported += o.reported;
  false_alarms += o.false_alarms;
  instances_found += o.instances_found;
  found_iou25 += o.found_iou25;
  found_iou50 += o.found_iou50;
  return *this;
}

ObstacleListCounts CountObstacleList(const Sample& sample, const std::vector<Box>& boxes) {
  ObstacleListCounts counts;
  counts.reported = static_cast<int>(boxes.size());
  for (const Box& b : boxes)
    counts.false_alarms += cv::countNonZero(sample.obstacle(b.rect())) == 0;
  for (const ObstacleInstance& inst : sample.instances) {
    bool overlaps = false;
    double best_iou = 0;
    for (const Box& b : boxes) {
      overlaps = overlaps || !Intersect(b, inst.box).empty();
      best_iou = std::max(best_iou, BoxIoU(b, inst.box));
    }
    counts.instances_found += overlaps;
    counts.found_iou25 += best_iou >= 0.25;
    counts.found_iou50 += best_iou >= 0.5;
  }
  return counts;
}

std::vector<DetectedObstacle> BoxListObstacles(const std::vector<ScoredBox>& map_boxes,
                                               const PipelineParams& params, float min_score,
                                               int min_area) {
  std::vector<DetectedObstacle> candidates;
  for (const ScoredBox& b : map_boxes) {
    if (b.box.area() < min_area) continue;
    const float score = static_cast<float>(CalibratedScore(params.obstacle_calibration, b.score));
    if (score >= min_score) candidates.push_back({b.box, b.box.area(), 0.f, 0.f, b.score, score});
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const DetectedObstacle& a, const DetectedObstacle& b) { return a.score > b.score; });
  std::vector<DetectedObstacle> kept;
  for (const DetectedObstacle& c : candidates)
    if (std::none_of(kept.begin(), kept.end(),
                     [&](const DetectedObstacle& k) { return SameObject(k.box, c.box); }))
      kept.push_back(c);
  return kept;
}

namespace {

// The components of `map` over each threshold, cut at each minimum score.
void SweepComponents(const Sample& sample, const cv::Mat1f& map, const FrameTrace& trace,
                     const PipelineParams& params, const char* rule,
                     const std::vector<float>& thresholds, const std::vector<float>& min_scores,
                     std::map<std::string, ObstacleListCounts>& out) {
  for (const float threshold : thresholds) {
    DetectOptions options;
    options.obstacle_threshold = threshold;
    options.min_obstacle_score = 0.f;  // every component scored once, then cut per minimum
    const std::vector<DetectedObstacle> scored =
        ScoreObstacles(map, trace.accumulated.boxes, params, options);
    for (const float min_score : min_scores) {
      std::vector<DetectedObstacle> kept;
      for (const DetectedObstacle& o : scored)
        if (o.score >= min_score) kept.push_back(o);
      out[RuleKey(rule, threshold, min_score)] = CountObstacleList(sample, BoxesOf(kept));
    }
  }
}

}  // namespace

std::map<std::string, ObstacleListCounts> SweepObstacleLists(const Sample& sample,
                                                             const FrameTrace& trace,
                                                             const PipelineParams& params,
                                                             const cv::Mat1f* calibrated,
                                                             const ObstacleListSweepGrid& grid) {
  std::map<std::string, ObstacleListCounts> out;
  SweepComponents(sample, trace.components, trace, params, "components", grid.thresholds,
                  grid.min_scores, out);
  if (calibrated != nullptr)
    SweepComponents(sample, *calibrated, trace, params, "calibrated", grid.calibrated_thresholds,
                    grid.min_scores, out);
  for (const float min_score : grid.min_scores)
    out[BoxesKey(min_score)] = CountObstacleList(
        sample, BoxesOf(BoxListObstacles(trace.accumulated.boxes, params, min_score,
                                         DetectOptions{}.min_obstacle_area)));
  return out;
}

nlohmann::json ObstacleListSweepToJson(const std::map<std::string, ObstacleListCounts>& sweep,
                                       int instances, int frames) {
  const auto share = [](int count, int of) -> nlohmann::json {
    return of > 0 ? nlohmann::json(static_cast<double>(count) / of) : nlohmann::json();
  };
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, c] : sweep) {
    const std::size_t slash = key.rfind('/');
    out[key.substr(0, slash)][key.substr(slash + 1)] = {
        {"found_iou50", share(c.found_iou50, instances)},
        {"found_iou25", share(c.found_iou25, instances)},
        {"instances_found", share(c.instances_found, instances)},
        {"false_alarms_per_frame", share(c.false_alarms, frames)},
        {"reported_per_frame", share(c.reported, frames)}};
  }
  return out;
}

std::string FormatObstacleListSweep(const std::map<std::string, ObstacleListCounts>& sweep,
                                    int instances, int frames) {
  const auto share = [](int count, int of) {
    return of > 0 ? static_cast<double>(count) / of : 0.0;
  };
  std::string out =
      "Obstacle list by reporting rule (components@map threshold / min score; boxes / min score)\n";
  char line[160];
  std::snprintf(line, sizeof line, "%-22s %9s %9s %9s %9s %9s\n", "rule", "IoU 0.5", "IoU 0.25",
                "overlap", "FA/frame", "per frame");
  out += line;
  for (const auto& [key, c] : sweep) {
    std::snprintf(line, sizeof line, "%-22s %9.3f %9.3f %9.3f %9.3f %9.2f\n", key.c_str(),
                  share(c.found_iou50, instances), share(c.found_iou25, instances),
                  share(c.instances_found, instances), share(c.false_alarms, frames),
                  share(c.reported, frames));
    out += line;
  }
  return out;
}

}  // namespace tod
