#include "core/pipeline/probability_map.h"

#include <algorithm>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "core/pipeline/superpixel_share.h"
#include "core/proposals/edge_box_scorer.h"

namespace tod {

std::vector<int> GatedByOrdr(const std::vector<float>& ordr, const FusionParams& params) {
  std::vector<int> order(ordr.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ordr[a] > ordr[b]; });
  order.resize(static_cast<std::size_t>(params.keep_ratio * static_cast<float>(ordr.size())));
  return order;
}

std::vector<float> FuseScores(const std::vector<float>& ordr, const std::vector<float>& obdr,
                              const FusionParams& params) {
  std::vector<float> fused(ordr.size(), 0.f);
  for (int i : GatedByOrdr(ordr, params))
    fused[i] = ordr[i] + params.beta1 * (static_cast<std::size_t>(i) < obdr.size() ? obdr[i] : 0.f);
  return fused;
}

std::vector<ScoredBox> RankedAboveThreshold(const std::vector<ScoredBox>& boxes, float min_score) {
  std::vector<ScoredBox> kept;
  for (const auto& b : boxes)
    if (b.score > min_score) kept.push_back(b);
  std::stable_sort(kept.begin(), kept.end(),
                   [](const ScoredBox& a, const ScoredBox& b) { return a.score > b.score; });
  return kept;
}

std::vector<ScoredBox> MapBoxes(const std::vector<ScoredBox>& boxes,
                                const ProbabilityMapParams& params) {
  const std::vector<ScoredBox> ranked = RankedAboveThreshold(boxes, params.min_score);
  std::vector<ScoredBox> kept = NonMaximumSuppression(ranked, params.nms_iou, params.max_boxes);
  kept.resize(static_cast<std::size_t>(params.top_fraction * kept.size()));
  return kept;
}

float ObstacleEvidence(const Box& component, const std::vector<ScoredBox>& map_boxes) {
  float evidence = 0.f;
  for (const ScoredBox& b : map_boxes)
    if (!Intersect(b.box, component).empty()) evidence = std::max(evidence, b.score);
  return evidence;
}

namespace {

// The accumulated scores and their largest value (before the map is divided by it).
struct ScoreSum {
  cv::Mat1f sum;
  double peak = 0;
};

// The paper's accumulation: a 2-D difference image, +s at each box's top-left and -s past its
// right / bottom, then prefix sums. The peak is taken from the double sums.
ScoreSum AccumulateWholeBoxes(const std::vector<ScoredBox>& kept, cv::Size image_size) {
  cv::Mat1d diff = cv::Mat1d::zeros(image_size.height + 1, image_size.width + 1);
  for (const ScoredBox& k : kept) {
    const Box b = ClipToImage(k.box, image_size.width, image_size.height);
    if (b.empty()) continue;
    const double s = k.score;
    diff(b.y, b.x) += s;
    diff(b.y, b.right()) -= s;
    diff(b.bottom(), b.x) -= s;
    diff(b.bottom(), b.right()) += s;
  }
  ScoreSum out{cv::Mat1f(image_size, 0.f)};
  std::vector<double> column(image_size.width + 1, 0.0);
  for (int y = 0; y < image_size.height; ++y) {
    double run = 0;
    for (int x = 0; x < image_size.width; ++x) {
      column[x] += diff(y, x);
      run += column[x];
      out.sum(y, x) = static_cast<float>(run);
      out.peak = std::max(out.peak, run);
    }
  }
  return out;
}

Status SharesHaveSuperpixels(bool superpixel_shares, const MapSuperpixels* superpixels) {
  if (!superpixel_shares || superpixels != nullptr) return Status::Ok();
  return Status::InvalidArgument(
      "probability map: superpixel shares were asked for without the frame's superpixels");
}

ScoreSum AccumulateShares(const std::vector<ScoredBox>& kept, cv::Size image_size,
                          const MapSuperpixels& superpixels) {
  ScoreSum out{cv::Mat1f(image_size, 0.f)};
  SuperpixelShare share(superpixels.superpixels, superpixels.crop);
  for (const ScoredBox& k : kept) share.PaintAdd(k.box, k.score, &out.sum);
  cv::minMaxLoc(out.sum, nullptr, &out.peak);
  return out;
}

}  // namespace

MapAccumulation WeighMapBoxes(std::vector<ScoredBox> map_boxes,
                              const std::vector<ScoredBox>& frame_boxes,
                              const BoxIsolationParams& isolation) {
  MapAccumulation out;
  out.weighted = map_boxes;
  if (isolation.exponent != 0.f) {
    const std::vector<float> weights = IsolationWeights(map_boxes, frame_boxes, isolation);
    for (std::size_t i = 0; i < out.weighted.size(); ++i) out.weighted[i].score *= weights[i];
  }
  out.boxes = std::move(map_boxes);
  return out;
}

MapAccumulation AccumulatedBoxes(const std::vector<ScoredBox>& boxes,
                                 const ProbabilityMapParams& params) {
  return WeighMapBoxes(MapBoxes(boxes, params), boxes, params.isolation);
}

Result<cv::Mat1f> PaintProbabilityMap(const MapAccumulation& accumulated, cv::Size image_size,
                                      bool superpixel_shares, const MapSuperpixels* superpixels) {
  if (Status ready = SharesHaveSuperpixels(superpixel_shares, superpixels); !ready.ok())
    return ready;
  ScoreSum painted = superpixel_shares
                         ? AccumulateShares(accumulated.weighted, image_size, *superpixels)
                         : AccumulateWholeBoxes(accumulated.weighted, image_size);
  cv::Mat1f& prob = painted.sum;
  if (painted.peak > 0) prob *= 1.0 / painted.peak;
  cv::max(prob, 0.f, prob);  // rounding in the prefix sums must not leave tiny negatives
  return prob;
}

Result<cv::Mat1f> AccumulateProbabilityMap(const std::vector<ScoredBox>& boxes, cv::Size image_size,
                                           const ProbabilityMapParams& params,
                                           const MapSuperpixels* superpixels) {
  // Checked before the boxes are found, as PaintProbabilityMap checks again.
  if (Status ready = SharesHaveSuperpixels(params.superpixel_shares, superpixels); !ready.ok())
    return ready;
  return PaintProbabilityMap(AccumulatedBoxes(boxes, params), image_size, params.superpixel_shares,
                             superpixels);
}

Status CalibratedMapAvailable(const ObstacleCalibration& calibration) {
  if (calibration.fitted) return Status::Ok();
  return Status::FailedPrecondition(
      "the model has no fitted obstacle calibration (made before `tod train` fitted one): "
      "the calibrated map needs it; ask for the normalized map");
}

Result<cv::Mat1f> CalibratedProbabilityMap(const std::vector<ScoredBox>& fused_boxes,
                                           cv::Size image_size,
                                           const ObstacleCalibration& calibration,
                                           const Superpixels& superpixels, const Box& crop) {
  if (Status available = CalibratedMapAvailable(calibration); !available.ok()) return available;
  cv::Mat1f map(image_size, 0.f);
  SuperpixelShare share(superpixels, crop);
  for (const ScoredBox& b : fused_boxes)
    if (b.score > 0.f)
      share.PaintMax(b.box, static_cast<float>(CalibratedScore(calibration, b.score)), &map);
  return map;
}

std::vector<ObstacleComponent> ThresholdObstacles(const cv::Mat1f& probability, float threshold) {
  std::vector<ObstacleComponent> out;
  if (probability.empty()) return out;
  const cv::Mat1b mask = probability > threshold;
  // Only the mask's bounding box holds components, and it is usually a small part of the frame:
  // labelling the whole 2048 x 1024 mask took ~15 ms, most of the map stage. The box is grown to
  // even coordinates because OpenCV labels 2 x 2 blocks in raster order: with the block grid
  // where the whole frame has it, the components are numbered as on the whole frame, so their
  // order under equal peaks, their sums and their boxes (moved back by the origin) are the same
  // (ProbabilityMapTest.ComponentsOfTheMasksBoundingBoxAreThoseOfTheWholeMap).
  cv::Rect roi = cv::boundingRect(mask);
  if (roi.empty()) return out;
  const int x0 = roi.x & ~1, y0 = roi.y & ~1;
  roi = cv::Rect(x0, y0, roi.x + roi.width - x0, roi.y + roi.height - y0);
  cv::Mat1i labels;
  cv::Mat stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask(roi), labels, stats, centroids, 8, CV_32S);
  out.resize(std::max(0, n - 1));
  std::vector<double> sums(out.size(), 0.0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* label_row = labels[y];
    const float* p_row = probability[roi.y + y] + roi.x;
    for (int x = 0; x < labels.cols; ++x) {
      const int l = label_row[x];
      if (l == 0) continue;
      const float p = p_row[x];
      out[l - 1].peak = std::max(out[l - 1].peak, p);
      sums[l - 1] += p;
    }
  }
  for (int l = 1; l < n; ++l) {
    auto& c = out[l - 1];
    c.box = {roi.x + stats.at<int>(l, cv::CC_STAT_LEFT), roi.y + stats.at<int>(l, cv::CC_STAT_TOP),
             stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT)};
    c.area = stats.at<int>(l, cv::CC_STAT_AREA);
    c.mean = c.area > 0 ? static_cast<float>(sums[l - 1] / c.area) : 0.f;
  }
  std::stable_sort(
      out.begin(), out.end(),
      [](const ObstacleComponent& a, const ObstacleComponent& b) { return a.peak > b.peak; });
  return out;
}

}  // namespace tod
