// Pixel counting over binary masks in O(1) per box, and the training overlap of ALGORITHM.md §6.4:
// IoU(b, o) = |b ∩ mask_o| / (|mask_o| + |b| − |b ∩ mask_o|) with |b| = w·h, max over instances.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

// Integral image of (mask != 0) for a mask placed at `origin` in full-image coordinates.
class MaskPixelCounter {
 public:
  MaskPixelCounter() = default;  // counts nothing
  explicit MaskPixelCounter(const cv::Mat1b& mask, cv::Point origin = {0, 0});

  // Number of non-zero mask pixels inside `box` (full-image coordinates; any part of the box
  // outside the mask counts nothing).
  long long Count(const Box& box) const;
  long long total() const { return total_; }

 private:
  cv::Point origin_;
  cv::Mat1i integral_;  // (rows + 1) x (cols + 1); empty for an empty mask
  long long total_ = 0;
};

// O(1) mask IoU of a box against each GT obstacle instance (box-local integral per instance).
class MaskIoUTable {
 public:
  MaskIoUTable() = default;  // no instances: every IoU is 0
  // Fails when an instance's mask is not box.h x box.w (naming the instance id).
  static Result<MaskIoUTable> Build(const std::vector<ObstacleInstance>& instances);

  int num_instances() const { return static_cast<int>(instances_.size()); }
  // |b ∩ mask_o| for instance i.
  long long Intersection(const Box& box, int instance) const;
  // Mask IoU of §6.4 against instance i; 0 when both the box and the mask are empty.
  double IoU(const Box& box, int instance) const;
  // Max over instances of IoU(box, instance); 0 with no instances.
  double MaxIoU(const Box& box) const;
  // Max over instances of the box-vs-box IoU against the instances' tight boxes.
  double MaxBoxIoU(const Box& box) const;

 private:
  struct Instance {
    Box box;
    MaskPixelCounter pixels;
  };
  std::vector<Instance> instances_;
};

}  // namespace tod
