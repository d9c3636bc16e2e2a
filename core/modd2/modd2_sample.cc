// SampleFromModd2Annotation: the official large / small obstacle rules turned into the shared
// Sample type (ALGORITHM.md §9.2; MODD2-FORMAT.md "Water / large-small rules").
#include <opencv2/imgproc.hpp>

#include "core/modd2/modd2_ground_truth.h"
#include "core/modd2/modd2_reader.h"

namespace tod {
namespace {

bool AnyCornerIn(const cv::Mat1b& mask, const Box& b) {
  const int x0 = b.x;
  const int y0 = b.y;
  const int x1 = b.right() - 1;
  const int y1 = b.bottom() - 1;
  return mask(y0, x0) || mask(y1, x1) || mask(y1, x0) || mask(y0, x1);
}

bool Touches(const cv::Mat1b& mask, const Box& b) { return cv::countNonZero(mask(b.rect())) > 0; }

}  // namespace

Sample SampleFromModd2Annotation(const Modd2Annotation& annotation, const cv::Mat3b& image,
                                 const std::string& name, int min_obstacle_area) {
  const int width = image.cols;
  const int height = image.rows;
  Sample sample;
  sample.name = name;
  sample.image = image;

  const std::vector<cv::Point2d> sea_edge = CleanSeaEdge(annotation.sea_edge, width, height);
  const cv::Mat1b water = Modd2WaterMask(sea_edge, width, height);
  const cv::Mat1b above_sea_edge = Modd2AboveSeaEdgeMask(sea_edge, width, height);
  // The freezone is taken from the water before large obstacles dent it, as the official code does.
  const cv::Mat1b freezone = Modd2Freezone(water);

  cv::Mat1b all_boxes(height, width, static_cast<unsigned char>(0));
  sample.obstacle = cv::Mat1b(height, width, static_cast<unsigned char>(0));
  for (std::size_t i = 0; i < annotation.obstacles.size(); ++i) {
    const Modd2PixelBox box = RoundModd2Box(annotation.obstacles[i], width, height);
    if (!box.valid) continue;
    const cv::Rect rect = box.pixels.rect();
    // Every annotated box leaves the road: large ones are not water, dropped small ones are
    // neither counted as road nor as obstacle (they become ignore).
    all_boxes(rect).setTo(255);
    if (Touches(above_sea_edge, box.pixels)) continue;    // large obstacle
    if (box.official_area < min_obstacle_area) continue;  // too small to count
    if (AnyCornerIn(freezone, box.pixels)) continue;      // above the water edge
    sample.obstacle(rect).setTo(255);
    ObstacleInstance instance;
    instance.id = static_cast<int>(i) + 1;  // 1-based row of annotations.obstacles
    instance.box = box.pixels;
    instance.mask = cv::Mat1b(rect.height, rect.width, static_cast<unsigned char>(255));
    sample.instances.push_back(std::move(instance));
  }
  cv::Mat1b not_boxes;
  cv::bitwise_not(all_boxes, not_boxes);
  cv::bitwise_and(water, not_boxes, sample.road);
  cv::Mat1b labelled;
  cv::bitwise_or(sample.road, sample.obstacle, labelled);
  cv::bitwise_not(labelled, sample.ignore);
  return sample;
}

}  // namespace tod
