// A minimal parallel loop over frame indices: frames are independent, so training and evaluation
// spread them over the cores. Each index runs exactly once; results are written by index, so the
// outcome does not depend on the thread count.
#pragma once

#include <functional>
#include <vector>

#include "core/base/status.h"

namespace tod {

// Runs body(i) for every i in [0, count) on up to `threads` threads (0 = all cores) and returns
// one Status per index: what body returned, or Internal naming the exception body threw. An
// exception in one frame thus becomes that frame's error, never std::terminate, and the other
// frames still run.
std::vector<Status> ParallelFor(int count, int threads, const std::function<Status(int)>& body);

}  // namespace tod
