// The value types every stage shares. One convention everywhere: 0-based pixel boxes, half-open
// extents [x, x + w) x [y, y + h). Conversions from 1-based / inclusive sources happen once, at
// the I/O boundary that reads them.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace tod {

struct Box {
  int x = 0;
  int y = 0;
  int w = 0;
  int h = 0;

  int right() const { return x + w; }   // one past the last column
  int bottom() const { return y + h; }  // one past the last row
  long long area() const { return static_cast<long long>(w) * h; }
  bool empty() const { return w <= 0 || h <= 0; }
  cv::Rect rect() const { return {x, y, w, h}; }
  static Box FromRect(const cv::Rect& r) { return {r.x, r.y, r.width, r.height}; }
  bool operator==(const Box&) const = default;
};

// Intersection of two boxes (empty box when disjoint).
Box Intersect(const Box& a, const Box& b);
// Box clipped to [0, width) x [0, height).
Box ClipToImage(const Box& b, int width, int height);
// Intersection over union of the pixel sets of two boxes; 0 when both are empty.
double BoxIoU(const Box& a, const Box& b);

struct ScoredBox {
  Box box;
  float score = 0.f;
};

// One annotated obstacle: its tight box and its mask restricted to that box (255 = obstacle).
struct ObstacleInstance {
  int id = 0;      // dataset instance id (LAF: class * 1000 + k)
  Box box;         // tight box, full-image coordinates
  cv::Mat1b mask;  // box.h x box.w
  long long pixel_count() const { return cv::countNonZero(mask); }
};

// What a dataset's `road` mask holds: a labelled drivable surface (LAF free space, MODDv2 water),
// or, for anomaly-benchmark masks that have no road label, every pixel that is neither obstacle
// nor void ("not an obstacle": road and the rest of the scene together).
enum class FreeSpace { kRoadLabel, kNotObstacle };

// One annotated frame, whatever the dataset. Masks are full-frame, 255 = member.
// road: free space (see FreeSpace), obstacles excluded.
// obstacle: union of obstacle instances. ignore: neither counted as road nor as obstacle.
struct Sample {
  std::string name;        // stem used for outputs, e.g. "scene_000001_000010"
  std::string image_path;  // where the image came from (for messages)
  cv::Mat3b image;         // BGR, 8-bit
  cv::Mat1b road;
  cv::Mat1b obstacle;
  cv::Mat1b ignore;
  std::vector<ObstacleInstance> instances;
  FreeSpace free_space = FreeSpace::kRoadLabel;
};

}  // namespace tod
