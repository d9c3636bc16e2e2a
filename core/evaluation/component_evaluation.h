// The SegmentMeIfYouCan component metrics of `tod eval` (core/metrics/component_metrics.h) on a
// split, for a score map and for the obstacle list as served.
//
// A score map is binarised at the split's threshold of best pixel F1, which is known only after
// the last frame, so each frame's map (as served: 8 bits) is kept until then with its truth and
// void masks, PNG-compressed: a frame's map is mostly zero, tens of kilobytes instead of 2 MB.
// The obstacle list needs no threshold: its pixels are measured as each frame is evaluated.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/metrics/component_metrics.h"
#include "core/pipeline/detector.h"

namespace tod {

// Outside the region of interest: every pixel neither free space (the road label or, without
// one, every non-void non-obstacle pixel) nor obstacle, as the pixel metrics count them.
cv::Mat1b ComponentVoidMask(const Sample& sample);

// The pixels of the reported obstacles: the components of `components_map` > threshold whose
// boxes are the obstacles' boxes (ThresholdObstacles labels the same way, 8-connected).
cv::Mat1b ReportedObstaclePixels(const cv::Mat1f& components_map, float threshold,
                                 const std::vector<DetectedObstacle>& obstacles);

class ComponentMapStore {
 public:
  // Keeps the frame's map quantised as served (ProbabilityTo8Bit) with the sample's masks.
  Status Add(const cv::Mat1f& probability, const Sample& sample);
  // The components of every kept map binarised at v >= level (8-bit), pooled.
  Result<ComponentSummary> Measure(int level, int threads) const;
  int frames() const { return static_cast<int>(frames_.size()); }

 private:
  struct Kept {
    std::vector<std::uint8_t> map_png, truth_png, void_png;
  };
  std::vector<Kept> frames_;
};

}  // namespace tod
