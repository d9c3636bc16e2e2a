// Image channels shared by the edge sources (ALGORITHM.md §3.4, "Preferred pipeline" step 1 and
// the "Zero-training fallback"): float LUV colour, triangle smoothing, colour gradient (max over
// the LUV channels) and the SED-style channel stack of the pixel edge classifier.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace tod {

// BGR 8-bit -> float CIE L*u*v* divided by 100, so L lies in [0,1] and u, v roughly in [-1.4,2.2]:
// one unit for all three channels, which keeps "max over channels" meaningful.
cv::Mat3f BgrToLuv(const cv::Mat3b& bgr);

// Separable triangle filter of the given radius (kernel 1,2,..,r+1,..,2,1 normalised; reflected
// border), as pdollar's convTri. radius <= 0 returns a copy. Works on any float Mat.
cv::Mat TriangleSmooth(const cv::Mat& src, int radius);

// Central-difference colour gradient. At every pixel the channel with the largest squared
// magnitude wins (as in SED's gradientMag); borders are replicated.
struct ColourGradient {
  cv::Mat1f magnitude;
  cv::Mat1f orientation;  // radians in [0, pi); empty unless requested
};
ColourGradient ComputeColourGradient(const cv::Mat3f& luv, bool with_orientation);

// Splits the gradient magnitude over `kOrientationBins` orientation bins centred on 0, 45, 90 and
// 135 degrees. With the doubled angle phi = 2 theta (orientation is defined modulo 180 degrees),
// bin b gets max(0, cos(phi - 90 b deg)) / (|cos phi| + |sin phi|): all of it at a bin centre,
// half-half midway between two centres, and no trigonometry needed when computed from (dx, dy).
inline constexpr int kOrientationBins = 4;
std::array<cv::Mat1f, kOrientationBins> OrientationHistograms(const ColourGradient& gradient);

// The stack of 13 channels of the pixel edge classifier, all at half resolution (SED's shrink 2):
// cell (i, j) covers full-resolution pixels [2j, 2j+2) x [2i, 2i+2) of the image padded by
// replication to even size.
enum EdgeChannel : int {
  kChanL = 0,
  kChanU,
  kChanV,
  kChanGradFull,    // gradient magnitude computed at full resolution, area-averaged to the cell
  kChanOrientFull,  // + 0..3: oriented histograms at full resolution
  kChanGradHalf = kChanOrientFull + kOrientationBins,  // gradient of the half-resolution image
  kChanOrientHalf,                                     // + 0..3
  kNumEdgeChannels = kChanOrientHalf + kOrientationBins,
};

struct EdgeChannelParams {
  int image_smooth_radius = 1;    // triangle radius on the full-resolution LUV image
  int channel_smooth_radius = 1;  // triangle radius on every half-resolution channel
};

struct EdgeChannels {
  std::vector<cv::Mat1f> planes;  // kNumEdgeChannels planes, each rows() x cols()
  int rows() const { return planes.empty() ? 0 : planes[0].rows; }
  int cols() const { return planes.empty() ? 0 : planes[0].cols; }
};

// Cells per dimension of the half-resolution grid: ceil(n / 2).
inline int HalfSize(int n) { return (n + 1) / 2; }

// Empty input gives empty planes.
EdgeChannels ComputeEdgeChannels(const cv::Mat3b& bgr, const EdgeChannelParams& params = {});

}  // namespace tod
