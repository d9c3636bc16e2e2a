// The paper's curves as PNG line charts (axes, ticks, legend; one line a variant):
// recall vs proposals at IoU 0.7, recall vs IoU at 1000, AR vs proposals, pixel ROC, and the
// pixel precision-recall curve of the served 8-bit map (the anomaly-segmentation benchmarks').
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/evaluation/evaluator.h"

namespace tod {

struct PlotSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
};

struct PlotSpec {
  std::string title;
  std::string x_label;
  std::string y_label;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
};

// Renders a chart (820 x 600 BGR).
cv::Mat3b RenderLineChart(const PlotSpec& spec, const std::vector<PlotSeries>& series);

// Writes recall_vs_proposals.png, recall_vs_iou.png, ar_vs_proposals.png, pixel_roc.png and
// pixel_pr.png into dir.
Status WriteEvalPlots(const EvalReport& report, const std::string& dir);

}  // namespace tod
