// MODDv2 reader (issue 5, ../shared/docs/MODD2-FORMAT.md): left camera images and the per-frame
// MAT annotations (sea_edge, obstacles) into the same Sample type as Lost and Found.
// Water (below the cleaned sea edge) plays the road; large obstacles (touching the area above the
// sea edge) are cut out of the water; small boxes under 25 px are dropped; the rest is ignore.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/data/dataset.h"

namespace tod {

struct Modd2Options {
  bool rectified = false;     // framesRectified + annotationsV2_rectified
  int min_obstacle_area = 25;  // px; smaller small obstacles are dropped from the ground truth
  // Sequence split; empty = the versioned default split shipped in the repository.
  std::vector<std::string> train_sequences;
  std::vector<std::string> test_sequences;
};

// split: "train" or "test" (or "all").
Result<std::unique_ptr<Dataset>> OpenModd2Dataset(const std::string& root, const std::string& split,
                                                  const Modd2Options& options = {});
bool LooksLikeModd2(const std::string& root);

struct Modd2Annotation {
  std::vector<cv::Point2d> sea_edge;   // 1-based x, y as stored (may hold NaN / Inf)
  std::vector<cv::Rect2d> obstacles;   // 1-based x, y, w, h as stored
};
// Reads one annotation MAT file; errors name the file and the field.
Result<Modd2Annotation> ReadModd2Annotation(const std::string& mat_path);
// Builds masks and instances from an annotation for an image of the given size.
Sample SampleFromModd2Annotation(const Modd2Annotation& annotation, const cv::Mat3b& image,
                                 const std::string& name, int min_obstacle_area = 25);

}  // namespace tod
