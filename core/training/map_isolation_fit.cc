#include "core/training/map_isolation_fit.h"

#include <cmath>

#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/probability_map.h"

namespace tod {

std::vector<float> DefaultIsolationExponents() { return {0.f, 0.5f, 1.f, 2.f, 3.f, 4.f}; }

MapIsolationFit::MapIsolationFit(std::vector<float> exponents, const PipelineParams& params,
                                 int frames)
    : exponents_(std::move(exponents)),
      params_(params),
      pixels_(exponents_.size()),
      components_(exponents_.size(), std::vector<std::vector<std::pair<double, int>>>(frames)) {}

Status MapIsolationFit::AddFrame(int frame, const Sample& sample, const MapSuperpixels& superpixels,
                                 const std::vector<ScoredBox>& fused) {
  DetectOptions every_component;
  every_component.min_obstacle_score = -1.f;
  // The map's boxes do not depend on the weights: found once, weighed per candidate.
  const std::vector<ScoredBox> map_boxes = MapBoxes(fused, params_.probability_map);
  for (std::size_t c = 0; c < exponents_.size(); ++c) {
    PipelineParams params = params_;
    params.probability_map.isolation.exponent = exponents_[c];
    const MapAccumulation accumulated =
        WeighMapBoxes(map_boxes, fused, params.probability_map.isolation);
    Result<cv::Mat1f> made = PaintProbabilityMap(
        accumulated, sample.image.size(), params.probability_map.superpixel_shares, &superpixels);
    if (!made.ok()) return made.status();
    const cv::Mat1f& map = *made;
    const Result<cv::Mat1f> components =
        ObstacleComponentsMap(accumulated, sample.image.size(), params, MapKind::kNormalized, map);
    if (!components.ok()) return components.status();
    std::vector<std::pair<double, int>> found;
    for (const DetectedObstacle& o :
         ScoreObstacles(*components, accumulated.boxes, params, every_component))
      found.emplace_back(o.evidence, cv::countNonZero(sample.obstacle(o.box.rect())) > 0 ? 1 : 0);
    std::lock_guard lock(mutex_);
    if (Status st = pixels_[c].Add(map, sample.obstacle, sample.road); !st.ok()) return st;
    components_[c][frame] = std::move(found);
  }
  return Status::Ok();
}

int MapIsolationFit::Best() const {
  std::lock_guard lock(mutex_);
  int best = 0;
  double best_ap = -1;
  for (std::size_t c = 0; c < exponents_.size(); ++c) {
    const double ap = pixels_[c].Ap();
    // Strictly better only: on a tie the earlier (smaller) exponent stays. NaN (no obstacle
    // pixel) never wins, so such data keeps the first candidate.
    if (std::isfinite(ap) && ap > best_ap) best = static_cast<int>(c), best_ap = ap;
  }
  return best;
}

std::vector<std::pair<double, int>> MapIsolationFit::Components(int candidate) const {
  std::lock_guard lock(mutex_);
  std::vector<std::pair<double, int>> all;
  for (const auto& frame : components_[candidate])
    all.insert(all.end(), frame.begin(), frame.end());
  return all;
}

nlohmann::json MapIsolationFit::ToJson() const {
  const int best = Best();
  nlohmann::json candidates = nlohmann::json::array();
  std::lock_guard lock(mutex_);
  for (std::size_t c = 0; c < exponents_.size(); ++c) {
    const double ap = pixels_[c].Ap();
    candidates.push_back(
        {{"exponent", exponents_[c]}, {"ap", std::isfinite(ap) ? nlohmann::json(ap) : nullptr}});
  }
  return {{"candidates", candidates}, {"exponent", exponents_[best]}};
}

}  // namespace tod
