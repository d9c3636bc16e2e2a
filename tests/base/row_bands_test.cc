#include "core/base/row_bands.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace tod {
namespace {

// OpenCV's pool width for the scope of one test.
class PoolWidth {
 public:
  explicit PoolWidth(int threads) : before_(cv::getNumThreads()) { cv::setNumThreads(threads); }
  ~PoolWidth() { cv::setNumThreads(before_); }
  PoolWidth(const PoolWidth&) = delete;
  PoolWidth& operator=(const PoolWidth&) = delete;

 private:
  int before_;
};

cv::Mat1f Triangle(int radius) {
  cv::Mat1f kernel(1, 2 * radius + 1);
  for (int i = 0; i < kernel.cols; ++i)
    kernel(0, i) = static_cast<float>(radius + 1 - std::abs(i - radius));
  return kernel / cv::sum(kernel)[0];
}

TEST(ForEachRowBand, OneThreadVisitsAllRowsAtOnce) {
  const PoolWidth pool(1);
  std::vector<cv::Range> calls;
  ForEachRowBand(3 * kRowsPerBand + 1, [&](const cv::Range& rows) { calls.push_back(rows); });
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0], cv::Range(0, 3 * kRowsPerBand + 1));
}

TEST(ForEachRowBand, VisitsEveryRowOnceInBandsOfAtMostTheBandHeight) {
  const PoolWidth pool(3);
  for (const int rows : {0, 1, kRowsPerBand - 1, kRowsPerBand, kRowsPerBand + 1, 1000}) {
    std::vector<int> visits(static_cast<size_t>(rows), 0);
    ForEachRowBand(rows, [&](const cv::Range& band) {
      EXPECT_LE(band.size(), kRowsPerBand);
      EXPECT_EQ(band.start % kRowsPerBand, 0);
      for (int r = band.start; r < band.end; ++r) ++visits[static_cast<size_t>(r)];
    });
    for (int r = 0; r < rows; ++r) EXPECT_EQ(visits[static_cast<size_t>(r)], 1) << rows << " " << r;
  }
}

// The reference is one cv::sepFilter2D call over the whole image. Rows just past band borders,
// kernels wider than a band and a view into a larger image (whose rows beyond the view both the
// reference and the bands read) must all give the same pixels, bit for bit, on 1 and 3 threads.
TEST(SepFilterInRowBands, GivesThePixelsOfOneWholeImageCall) {
  cv::Mat3f parent(3 * kRowsPerBand + 17, 97);
  cv::RNG rng(11);
  rng.fill(parent, cv::RNG::UNIFORM, -1.f, 1.f);
  const cv::Mat3f view = parent(cv::Rect(5, 9, 80, 2 * kRowsPerBand + 3));
  for (const cv::Mat3f& image : {parent, view}) {
    for (const int radius : {1, 4, kRowsPerBand + 2}) {
      const cv::Mat1f kernel = Triangle(radius);
      cv::Mat reference;
      cv::sepFilter2D(image, reference, image.depth(), kernel, kernel, cv::Point(-1, -1), 0.0,
                      cv::BORDER_REFLECT);
      for (const int threads : {1, 3}) {
        const PoolWidth pool(threads);
        const cv::Mat banded = SepFilterInRowBands(image, kernel, kernel);
        ASSERT_EQ(banded.type(), reference.type());
        EXPECT_EQ(cv::norm(banded, reference, cv::NORM_INF), 0.0)
            << "radius " << radius << ", " << threads << " threads, rows " << image.rows;
      }
    }
  }
}

}  // namespace
}  // namespace tod
