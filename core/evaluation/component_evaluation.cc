#include "core/evaluation/component_evaluation.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <tuple>

#include "core/pipeline/parallel.h"

namespace tod {
namespace {

Result<std::vector<std::uint8_t>> Png(const cv::Mat1b& mask) {
  std::vector<std::uint8_t> out;
  // Level 1: these masks are mostly zero and compress well at the fastest level.
  if (!cv::imencode(".png", mask, out, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    return Status::Internal("ComponentMapStore: PNG encoding failed");
  return out;
}

Result<cv::Mat1b> Unpng(const std::vector<std::uint8_t>& png) {
  cv::Mat decoded = cv::imdecode(png, cv::IMREAD_GRAYSCALE);
  if (decoded.empty()) return Status::Internal("ComponentMapStore: PNG decoding failed");
  return cv::Mat1b(decoded);
}

}  // namespace

cv::Mat1b ComponentVoidMask(const Sample& sample) {
  cv::Mat1b in_roi = (sample.road != 0) | (sample.obstacle != 0);
  return in_roi == 0;
}

cv::Mat1b ReportedObstaclePixels(const cv::Mat1f& components_map, float threshold,
                                 const std::vector<DetectedObstacle>& obstacles) {
  cv::Mat1b pixels(components_map.size(), std::uint8_t{0});
  if (obstacles.empty()) return pixels;
  const cv::Mat1b mask = components_map > threshold;
  cv::Mat1i labels;
  cv::Mat stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::set<std::tuple<int, int, int, int>> reported;
  for (const DetectedObstacle& o : obstacles) reported.insert({o.box.x, o.box.y, o.box.w, o.box.h});
  std::vector<std::uint8_t> keep(n, 0);
  for (int l = 1; l < n; ++l)
    keep[l] = reported.count({stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                              stats.at<int>(l, cv::CC_STAT_WIDTH),
                              stats.at<int>(l, cv::CC_STAT_HEIGHT)}) > 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* label = labels[y];
    std::uint8_t* out = pixels[y];
    for (int x = 0; x < labels.cols; ++x) out[x] = keep[label[x]] ? 255 : 0;
  }
  return pixels;
}

Status ComponentMapStore::Add(const cv::Mat1f& probability, const Sample& sample) {
  if (probability.size() != sample.obstacle.size())
    return Status::InvalidArgument("ComponentMapStore: map and masks differ in size");
  cv::Mat1b served;
  probability.convertTo(served, CV_8U, 255.0);  // as PixelHistogramAccumulator bins it
  Kept kept;
  for (auto [mask, png] : {std::pair{served, &kept.map_png},
                           std::pair{cv::Mat1b(sample.obstacle != 0), &kept.truth_png},
                           std::pair{ComponentVoidMask(sample), &kept.void_png}}) {
    Result<std::vector<std::uint8_t>> encoded = Png(mask);
    if (!encoded.ok()) return encoded.status();
    *png = std::move(encoded).value();
  }
  frames_.push_back(std::move(kept));
  return Status::Ok();
}

Result<ComponentSummary> ComponentMapStore::Measure(int level, int threads) const {
  std::vector<FrameComponents> per_frame(frames_.size());
  const std::vector<Status> done =
      ParallelFor(static_cast<int>(frames_.size()), threads, [&](int i) -> Status {
        Result<cv::Mat1b> map = Unpng(frames_[i].map_png);
        Result<cv::Mat1b> truth = Unpng(frames_[i].truth_png);
        Result<cv::Mat1b> void_mask = Unpng(frames_[i].void_png);
        if (!map.ok()) return map.status();
        if (!truth.ok()) return truth.status();
        if (!void_mask.ok()) return void_mask.status();
        const cv::Mat1b predicted = *map >= level;
        Result<FrameComponents> measured = MeasureComponents(predicted, *truth, *void_mask);
        if (!measured.ok()) return measured.status();
        per_frame[i] = std::move(measured).value();
        return Status::Ok();
      });
  for (const Status& st : done)
    if (!st.ok()) return st;
  ComponentAccumulator pooled;
  for (const FrameComponents& f : per_frame) pooled.Add(f);
  return pooled.Summary();
}

}  // namespace tod
