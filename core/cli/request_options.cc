#include "core/cli/request_options.h"

#include <opencv2/core/utility.hpp>

namespace tod::cli {

void AddFrameRequestOptions(CLI::App* cmd, DetectOptions* options) {
  options->budget_ms = kDefaultFrameBudgetMs;
  cmd->add_option("--frame-budget-ms", options->budget_ms,
                  "time a frame may take from decode to map, ms; past it, proposals and "
                  "regression degrade and the output says so (0 = no budget)")
      ->check(CLI::Range(0.0, 600000.0))
      ->capture_default_str();
  cmd->add_option("--threads-per-request", options->threads,
                  "cores one frame may use (window scans, features and regressors split over "
                  "them)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
}

void UseRequestThreadsForOpenCv(const DetectOptions& options) {
  cv::setNumThreads(std::max(1, options.threads));
}

}  // namespace tod::cli
