// Options `tod detect` and `tod bench` share with tod_server: the frame budget and the cores one
// frame may use, with the server's defaults.
#pragma once

#include <CLI/CLI.hpp>

#include "core/pipeline/detector.h"

namespace tod::cli {

inline constexpr double kDefaultFrameBudgetMs = 2000;  // tod_server's --frame-budget-ms default

// Adds --frame-budget-ms (default kDefaultFrameBudgetMs, 0 = none) and --threads-per-request
// (default 1), writing into `options`.
void AddFrameRequestOptions(CLI::App* cmd, DetectOptions* options);

// OpenCV's thread pool (process-wide; the pixel edge classifier's rows run on it) sized to the
// request's threads, as tod_server sizes it: "one core" then means one core.
void UseRequestThreadsForOpenCv(const DetectOptions& options);

}  // namespace tod::cli
