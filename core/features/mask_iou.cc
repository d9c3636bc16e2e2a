#include "core/features/mask_iou.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

namespace tod {

MaskPixelCounter::MaskPixelCounter(const cv::Mat1b& mask, cv::Point origin) : origin_(origin) {
  if (mask.empty()) return;
  cv::Mat1b members = mask != 0;
  members.setTo(1, members);
  cv::integral(members, integral_, CV_32S);
  total_ = integral_(mask.rows, mask.cols);
}

long long MaskPixelCounter::Count(const Box& box) const {
  if (integral_.empty()) return 0;
  const Box local = ClipToImage(Box{box.x - origin_.x, box.y - origin_.y, box.w, box.h},
                                integral_.cols - 1, integral_.rows - 1);
  if (local.empty()) return 0;
  const int x0 = local.x, y0 = local.y, x1 = local.right(), y1 = local.bottom();
  return static_cast<long long>(integral_(y1, x1)) - integral_(y0, x1) - integral_(y1, x0) +
         integral_(y0, x0);
}

Result<MaskIoUTable> MaskIoUTable::Build(const std::vector<ObstacleInstance>& instances) {
  MaskIoUTable table;
  table.instances_.reserve(instances.size());
  for (const ObstacleInstance& instance : instances) {
    if (instance.box.w < 0 || instance.box.h < 0 || instance.mask.rows != instance.box.h ||
        instance.mask.cols != instance.box.w) {
      return Status::InvalidArgument(
          "MaskIoUTable: instance " + std::to_string(instance.id) + " has a mask of " +
          std::to_string(instance.mask.cols) + "x" + std::to_string(instance.mask.rows) +
          " but its box is " + std::to_string(instance.box.w) + "x" +
          std::to_string(instance.box.h) + "; the mask must cover exactly the box");
    }
    table.instances_.push_back(
        {instance.box, MaskPixelCounter(instance.mask, {instance.box.x, instance.box.y})});
  }
  return table;
}

long long MaskIoUTable::Intersection(const Box& box, int instance) const {
  return instances_.at(instance).pixels.Count(box);
}

double MaskIoUTable::IoU(const Box& box, int instance) const {
  const Instance& gt = instances_.at(instance);
  const long long inter = gt.pixels.Count(box);
  const long long uni = gt.pixels.total() + std::max(0LL, box.area()) - inter;
  return uni > 0 ? static_cast<double>(inter) / static_cast<double>(uni) : 0.0;
}

double MaskIoUTable::MaxIoU(const Box& box) const {
  double best = 0.0;
  for (int i = 0; i < num_instances(); ++i) best = std::max(best, IoU(box, i));
  return best;
}

double MaskIoUTable::MaxBoxIoU(const Box& box) const {
  double best = 0.0;
  for (const Instance& gt : instances_) best = std::max(best, BoxIoU(box, gt.box));
  return best;
}

}  // namespace tod
