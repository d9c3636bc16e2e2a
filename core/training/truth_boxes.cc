#include "core/training/truth_boxes.h"

namespace tod {

ProposalSet TruthBoxes(const std::vector<ObstacleInstance>& obstacles, const OcclusionEdges& oaocc,
                       const MultilayerRegions& regions, const EdgeBoxParams& box_params,
                       bool multistride) {
  ProposalSet truth;
  for (int k = 0; k < regions.num_layers(); ++k) {
    const Box region = Intersect(regions.layers[k], oaocc.r1);
    const cv::Mat1f map = NormaliseToMax(RegionEdgeMap(oaocc, regions, k));
    if (map.empty()) continue;
    const EdgeBoxParams params = RegionBoxParams(box_params, k, regions.num_layers(), multistride);
    for (const ObstacleInstance& obstacle : obstacles) {
      const Box& b = obstacle.box;
      if (b.empty() || Intersect(b, region).area() != b.area()) continue;
      const Box local{b.x - region.x, b.y - region.y, b.w, b.h};
      truth.boxes.push_back(ScoredBox{b, ScoreSingleBox(map, local, params)});
      truth.layer.push_back(k);
    }
  }
  return truth;
}

}  // namespace tod
