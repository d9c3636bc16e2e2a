// Fuzzes SampleFromLafAnnotation, the core of the Lost and Found reader (core/data/laf_reader.cc):
// instanceIds and labelIds images in, road / obstacle / ignore masks and obstacle instances out,
// with the cross-check between the two annotation images.
// Input: width, height, the two images' types and flags, then one byte per pixel. Each byte gives
// a category and an id, written so that the two images mostly agree (the interesting case):
//   b % 4 == 0 ignore (instance b / 4 < 1000, label 0), 1 road (1000, label 1),
//   2 obstacle (instance 1001 + (b / 4) % 8, label 2 + b / 4), 3 anything (instance 990 + b / 4,
//   label b / 16: often a disagreement).
#include <cstddef>
#include <cstdint>
#include <set>
#include <vector>

#include "core/data/laf_reader.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;

// The reader keeps the PNGs' depth (IMREAD_UNCHANGED): 16-bit instanceIds and 8-bit labelIds in
// the dataset, anything a broken export might give here.
constexpr int kTypes[] = {CV_16UC1, CV_8UC1, CV_32SC1, CV_16UC3, CV_16SC1, CV_32FC1};

cv::Mat AsType(const cv::Mat1i& ids, int type) {
  cv::Mat out;
  ids.convertTo(out, CV_MAT_DEPTH(type));  // saturating, as a lossy export would be
  if (CV_MAT_CN(type) == 3) cv::merge(std::vector<cv::Mat>{out, out, out}, out);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tod::fuzz::Bytes in(data, size);
  const int width = 1 + in.U8() % 48;
  const int height = 1 + in.U8() % 48;
  const int instance_type = kTypes[in.U8() % std::size(kTypes)];
  const int label_type = kTypes[(in.U8() + 1) % std::size(kTypes)];
  const uint8_t flags = in.U8();
  cv::Mat1i instance_ids(height, width);
  cv::Mat1i label_ids(height, width);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int b = in.U8();
      const int id = b / 4;
      switch (b % 4) {
        case 0:
          instance_ids(y, x) = id, label_ids(y, x) = 0;
          break;
        case 1:
          instance_ids(y, x) = 1000, label_ids(y, x) = 1;
          break;
        case 2:
          instance_ids(y, x) = 1001 + id % 8, label_ids(y, x) = 2 + id;
          break;
        default:
          instance_ids(y, x) = 990 + id, label_ids(y, x) = id / 4;
          break;
      }
    }
  }
  const cv::Mat3b image(height, (flags & 1) ? width + 1 : width, cv::Vec3b(80, 90, 100));
  const cv::Mat instances = AsType(instance_ids, instance_type);
  const cv::Mat labels = (flags & 2) ? AsType(label_ids, label_type).rowRange(0, height - 1)
                                     : AsType(label_ids, label_type);
  const tod::Result<tod::Sample> sample =
      tod::SampleFromLafAnnotation(image, instances, labels, "fuzz", "fuzz");
  if (!sample.ok()) {
    Check(!sample.status().message().empty());
    return 0;
  }
  Check(sample->road.size() == image.size() && sample->obstacle.size() == image.size() &&
        sample->ignore.size() == image.size());
  // Every pixel is in exactly one of road, obstacle and ignore.
  const cv::Mat1b sum = sample->road / 255 + sample->obstacle / 255 + sample->ignore / 255;
  Check(cv::countNonZero(sum != 1) == 0);
  const cv::Rect frame(0, 0, image.cols, image.rows);
  std::set<int> ids;
  for (const tod::ObstacleInstance& instance : sample->instances) {
    Check(ids.insert(instance.id).second);
    Check(!instance.box.empty() && (instance.box.rect() & frame) == instance.box.rect());
    Check(instance.pixel_count() > 0);
  }
  return 0;
}
