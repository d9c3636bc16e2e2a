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
  bool rectified = false;  // framesRectified + annotationsV2_rectified
  // Small obstacles whose rounded w * h (the official size: one less than the pixel count on
  // each side, see RoundModd2Box) is below this are dropped from the ground truth.
  int min_obstacle_area = 25;
  // Sequence split. When both are empty: <root>/modd2_split.txt if present (see modd2_split.h),
  // else the versioned default split shipped in the repository (default_split.cc). With an
  // implicit split, a sequence folder the split does not know is an error; with these lists,
  // other folders are ignored. Sequences the split needs but the root lacks are always an error.
  std::vector<std::string> train_sequences;
  std::vector<std::string> test_sequences;
};

// split: "train" or "test" (or "all" = every sequence the split knows, including the ones kept
// out of testing). Lists the frames (annotation files of frames S+1..E for a sequence named
// kopeNN-CC-SSSSSSSS-EEEEEEEE, all annotation files for other names) and checks each has its
// left image; errors name the directory or file. Frame names are "<seq>_<%08d>L".
Result<std::unique_ptr<Dataset>> OpenModd2Dataset(const std::string& root, const std::string& split,
                                                  const Modd2Options& options = {});
bool LooksLikeModd2(const std::string& root);

struct Modd2Annotation {
  std::vector<cv::Point2d> sea_edge;  // 1-based x, y as stored (may hold NaN / Inf)
  std::vector<cv::Rect2d> obstacles;  // 1-based x, y, w, h as stored
};
// Reads one annotation MAT file; errors name the file and the field.
Result<Modd2Annotation> ReadModd2Annotation(const std::string& mat_path);
// Builds masks and instances from an annotation for an image of the given size, following the
// official evaluation code (modd2_ground_truth.h has the rules): water = area below the cleaned sea
// edge (poly2mask semantics); boxes rounded as filter_obstacles.m does; a box touching the area
// above the sea edge is large; a small box with rounded w * h < min_obstacle_area or a corner
// above the water edge is dropped. road = water minus every box; obstacle = union of the kept
// small boxes (instance id = 1-based row in annotations.obstacles, mask = the whole box);
// ignore = everything else.
Sample SampleFromModd2Annotation(const Modd2Annotation& annotation, const cv::Mat3b& image,
                                 const std::string& name, int min_obstacle_area = 25);

}  // namespace tod
