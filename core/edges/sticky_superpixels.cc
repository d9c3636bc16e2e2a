#include "core/edges/sticky_superpixels.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/base/row_bands.h"
#include "core/edges/superpixel_boundaries.h"
#include "core/edges/superpixel_refine.h"

namespace tod {
namespace {

StickyImage ViewOf(const cv::Mat3f& colour, const cv::Mat1f& edge) {
  return StickyImage{colour.cols, colour.rows, colour.ptr<float>(0), edge.ptr<float>(0)};
}

// Labels 0..n-1 in raster order: every pixel its own superpixel (ALGORITHM.md §3.2(1)).
std::vector<int> OneLabelPerPixel(int width, int height) {
  std::vector<int> labels(static_cast<size_t>(width) * height);
  for (size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<int>(i);
  return labels;
}

}  // namespace

// OpenCV runs this filter on one thread; bands of rows run on its pool instead, with the pixels
// of one call over the whole image (row_bands.h).
cv::Mat3f SmoothStickyColour(const cv::Mat3f& colour) {
  const cv::Mat1f kernel = (cv::Mat1f(1, 3) << 0.25f, 0.5f, 0.25f);
  return SepFilterInRowBands(colour, kernel, kernel);
}

Status ValidateSuperpixelInput(const cv::Mat3b& bgr, const cv::Mat1f& edge,
                               const StickySuperpixelParams& params) {
  if (bgr.empty()) return Status::InvalidArgument("sticky superpixels: the image is empty");
  if (edge.size() != bgr.size()) {
    return Status::InvalidArgument("sticky superpixels: edge map is " + std::to_string(edge.cols) +
                                   "x" + std::to_string(edge.rows) + " but the image is " +
                                   std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
  }
  if (!cv::checkRange(edge)) {
    return Status::InvalidArgument("sticky superpixels: edge map contains NaN or infinity");
  }
  if (params.k <= 0) return Status::InvalidArgument("sticky superpixels: params.k must be > 0");
  if (!(params.alpha >= 0.f && params.alpha <= 1.f)) {
    return Status::InvalidArgument("sticky superpixels: params.alpha must be in [0,1]");
  }
  if (!(params.beta >= 0.f && params.beta <= 1.f)) {
    return Status::InvalidArgument("sticky superpixels: params.beta must be in [0,1]");
  }
  if (params.iterations < 0) {
    return Status::InvalidArgument("sticky superpixels: params.iterations must be >= 0");
  }
  return Status::Ok();
}

Result<Superpixels> ComputeStickySuperpixels(const cv::Mat3b& bgr, const cv::Mat1f& edge,
                                             const StickySuperpixelParams& params) {
  if (Status status = ValidateSuperpixelInput(bgr, edge, params); !status.ok()) return status;
  const int width = bgr.cols;
  const int height = bgr.rows;
  const StickyWeights weights = StickyWeightsFor(params.k, params.alpha, params.beta);

  cv::Mat3f colour(bgr.size());
  ForEachRowBand(height, [&](const cv::Range& rows) {
    cv::Mat band = colour.rowRange(rows);
    bgr.rowRange(rows).convertTo(band, CV_32F, 1.0 / 255.0);
  });
  const cv::Mat1f edge_full = edge.isContinuous() ? edge : edge.clone();

  // Half resolution on the even-sized crop: 2·nIter sweeps, size weight ×¼ and position ×4 so
  // that superpixels come out the same size in full-resolution pixels.
  const int half_w = width / 2;
  const int half_h = height / 2;
  std::vector<int> flat;
  if (half_w >= 1 && half_h >= 1) {
    const cv::Rect even(0, 0, 2 * half_w, 2 * half_h);
    cv::Mat3f colour_half;
    cv::Mat1f edge_half;
    cv::resize(colour(even), colour_half, cv::Size(half_w, half_h), 0, 0, cv::INTER_AREA);
    cv::resize(edge_full(even), edge_half, cv::Size(half_w, half_h), 0, 0, cv::INTER_AREA);
    const cv::Mat3f smooth_half = SmoothStickyColour(colour_half);
    StickyWeights half_weights = weights;
    half_weights.size *= 0.25;
    half_weights.position *= 4.0;
    std::vector<int> half_labels = OneLabelPerPixel(half_w, half_h);
    RefineStickyLabels(ViewOf(smooth_half, edge_half), half_weights, 2 * params.iterations,
                       half_labels);
    // Nearest ×2 upsampling; odd last row/column replicate their neighbour.
    flat.resize(static_cast<size_t>(width) * height);
    ForEachRowBand(height, [&](const cv::Range& rows) {
      for (int y = rows.start; y < rows.end; ++y) {
        const int hy = std::min(y / 2, half_h - 1);
        for (int x = 0; x < width; ++x) {
          const int hx = std::min(x / 2, half_w - 1);
          flat[static_cast<size_t>(y) * width + x] =
              half_labels[static_cast<size_t>(hy) * half_w + hx];
        }
      }
    });
  } else {
    flat = OneLabelPerPixel(width, height);  // a 1-pixel-thin crop has no half resolution
  }

  const cv::Mat3f smooth_full = SmoothStickyColour(colour);
  RefineStickyLabels(ViewOf(smooth_full, edge_full), weights, params.iterations, flat);

  Superpixels result;
  result.labels = cv::Mat1i(height, width);
  std::copy(flat.begin(), flat.end(), result.labels.ptr<int>(0));
  RelabelConnectedComponents(result.labels);
  InsertSuperpixelBoundaries(edge_full, result.labels);
  result.count = CompactLabels(result.labels);
  return result;
}

}  // namespace tod
