#include "core/evaluation/plots.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

const cv::Scalar kPalette[] = {{31, 119, 180},  {14, 127, 255}, {44, 160, 44},   {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127}};

std::string Tick(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf,
                v == static_cast<long long>(v) && std::abs(v) >= 1 ? "%.0f" : "%.2f", v);
  return buf;
}

// "AP 0.512", or "AP n/a" when undefined (no obstacle pixel).
std::string ApLabel(double ap) {
  if (std::isnan(ap)) return "AP n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "AP %.3f", ap);
  return buf;
}

// The precision-recall curve drawn as the step function AP integrates: each operating point's
// precision held from the previous recall to its own. Straight segments between the points would
// suggest precision values no threshold of the 8-bit map gives (most visibly the long diagonal to
// recall 1 at t = 0, where all the pixels the map leaves at zero come in at once).
PlotSeries PrecisionRecallSteps(const std::string& label, const PrecisionRecallCurve& curve) {
  PlotSeries steps{label, {}, {}};
  double previous_recall = 0.0;
  for (std::size_t i = 0; i < curve.recall.size() && i < curve.precision.size(); ++i) {
    steps.x.insert(steps.x.end(), {previous_recall, curve.recall[i]});
    steps.y.insert(steps.y.end(), {curve.precision[i], curve.precision[i]});
    previous_recall = curve.recall[i];
  }
  return steps;
}

}  // namespace

cv::Mat3b RenderLineChart(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  const int width = 820, height = 600, left = 100, right = 20, top = 50, bottom = 70;
  cv::Mat3b img(height, width, cv::Vec3b(255, 255, 255));
  const cv::Rect area(left, top, width - left - right, height - top - bottom);
  auto px = [&](double x, double y) {
    const double fx = (x - spec.x_min) / std::max(1e-12, spec.x_max - spec.x_min);
    const double fy = (y - spec.y_min) / std::max(1e-12, spec.y_max - spec.y_min);
    return cv::Point(area.x + static_cast<int>(std::lround(fx * area.width)),
                     area.y + area.height - static_cast<int>(std::lround(fy * area.height)));
  };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (int i = 0; i <= 5; ++i) {  // grid and ticks
    const double x = spec.x_min + (spec.x_max - spec.x_min) * i / 5.0;
    const double y = spec.y_min + (spec.y_max - spec.y_min) * i / 5.0;
    cv::line(img, px(x, spec.y_min), px(x, spec.y_max), {230, 230, 230}, 1);
    cv::line(img, px(spec.x_min, y), px(spec.x_max, y), {230, 230, 230}, 1);
    cv::putText(img, Tick(x), px(x, spec.y_min) + cv::Point(-14, 22), font, 0.45, {0, 0, 0}, 1,
                cv::LINE_AA);
    cv::putText(img, Tick(y), px(spec.x_min, y) + cv::Point(-50, 5), font, 0.45, {0, 0, 0}, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, area, {0, 0, 0}, 1);
  cv::putText(img, spec.title, {left, 30}, font, 0.7, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(img, spec.x_label, {area.x + area.width / 2 - 60, height - 20}, font, 0.55, {0, 0, 0},
              1, cv::LINE_AA);
  cv::Mat3b ylabel(30, 300, cv::Vec3b(255, 255, 255));
  cv::putText(ylabel, spec.y_label, {5, 20}, font, 0.55, {0, 0, 0}, 1, cv::LINE_AA);
  cv::Mat3b rotated;
  cv::rotate(ylabel, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  rotated.copyTo(img(cv::Rect(5, top + std::max(0, (area.height - rotated.rows) / 2), rotated.cols,
                              rotated.rows)));
  // The legend sits right-aligned, as wide as its longest label.
  int label_width = 0;
  for (const PlotSeries& one : series)
    label_width = std::max(label_width, cv::getTextSize(one.label, font, 0.5, 1, nullptr).width);
  const int legend_x = area.x + area.width - std::max(230, label_width + 48);
  for (std::size_t s = 0; s < series.size(); ++s) {
    const cv::Scalar colour = kPalette[s % (sizeof kPalette / sizeof kPalette[0])];
    std::vector<cv::Point> pts;
    for (std::size_t i = 0; i < series[s].x.size() && i < series[s].y.size(); ++i)
      pts.push_back(px(std::clamp(series[s].x[i], spec.x_min, spec.x_max),
                       std::clamp(series[s].y[i], spec.y_min, spec.y_max)));
    if (pts.size() >= 2) cv::polylines(img, pts, false, colour, 2, cv::LINE_AA);
    const cv::Point legend(legend_x, area.y + 20 + 22 * static_cast<int>(s));
    cv::line(img, legend, legend + cv::Point(30, 0), colour, 3);
    cv::putText(img, series[s].label, legend + cv::Point(38, 5), font, 0.5, {0, 0, 0}, 1,
                cv::LINE_AA);
  }
  return img;
}

Status WriteEvalPlots(const EvalReport& report, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::Internal("cannot create " + dir + ": " + ec.message());
  auto to_double = [](const std::vector<int>& v) {
    return std::vector<double>(v.begin(), v.end());
  };
  std::vector<PlotSeries> at07, at1000, ar, roc, pr;
  auto add = [&](const std::string& name, const VariantCurves& c) {
    at07.push_back({name, to_double(c.n_grid), c.recall_at_07});
    at1000.push_back({name, c.iou_grid, c.recall_at_1000});
    ar.push_back({name, to_double(c.n_grid), c.average_recall});
  };
  for (const auto& v : ProposalVariants()) add(v, report.proposals.at(v));
  for (const auto& v : RegressionVariants()) add(v, report.regression.at(v));
  for (const auto& v : PixelMapVariants(report)) {
    roc.push_back({v, report.roc.at(v).fpr, report.roc.at(v).tpr});
    // The legend carries the AP, the area under the step curve.
    pr.push_back(PrecisionRecallSteps(v + " (" + ApLabel(report.average_precision.at(v)) + ")",
                                      report.precision_recall.at(v)));
  }
  const std::vector<std::pair<std::string, cv::Mat3b>> charts = {
      {"recall_vs_proposals.png", RenderLineChart({"Recall vs proposals (IoU 0.7)",
                                                   "number of proposals", "recall", 0, 1000, 0, 1},
                                                  at07)},
      {"recall_vs_iou.png",
       RenderLineChart({"Recall vs IoU (1000 proposals)", "IoU threshold", "recall", 0.5, 1, 0, 1},
                       at1000)},
      {"ar_vs_proposals.png", RenderLineChart({"Average recall vs proposals", "number of proposals",
                                               "average recall", 0, 1000, 0, 1},
                                              ar)},
      {"pixel_roc.png",
       RenderLineChart({"Pixel ROC", "false positive rate", "true positive rate", 0, 0.05, 0, 1},
                       roc)},
      {"pixel_pr.png",
       RenderLineChart({"Pixel precision-recall (8-bit map)", "recall", "precision", 0, 1, 0, 1},
                       pr)}};
  for (const auto& [name, img] : charts) {
    const std::string path = (std::filesystem::path(dir) / name).string();
    if (!cv::imwrite(path, img)) return Status::Internal("cannot write " + path);
  }
  return Status::Ok();
}

}  // namespace tod
