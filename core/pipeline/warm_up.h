// A warm-up detection on a small made-up frame, run once when a model is loaded and before it
// serves (tod_server, tod detect), as inference servers warm a model before they report ready.
//
// Why: the first detection in a process pays one-off costs that are not its frame's. OpenCV
// builds its colour-conversion tables on first use (BGR -> Luv alone measured 205 ms), the
// dynamic linker binds each library call on its first use, and the heap grows for the first
// time. Measured on real 2048 x 1024 frames, the first `tod detect` of a process took 1.3-1.6 s
// against 0.9-1.3 s for the same frame next, and under the default 2000 ms frame budget the
// proposal stage of that first frame could be cut short. The warm-up moves those costs to load
// time, out of every frame's budget and latency.
#pragma once

#include "core/base/status.h"
#include "core/pipeline/detector.h"

namespace tod {

struct WarmUpParams {
  // The made-up frame: a road-like gradient with a few dark blocks on it, so every stage (edges,
  // superpixels, occlusion, proposals, features, regressors, map) has work to do.
  int width = 512;
  int height = 256;
};

// Runs one detection without a budget on the made-up frame and returns its time in ms. A
// detector that cannot detect on it is broken: the error names the warm-up.
Result<double> WarmUp(const Detector& detector, const WarmUpParams& params = {});

// The made-up frame itself (deterministic).
cv::Mat3b WarmUpFrame(const WarmUpParams& params);

}  // namespace tod
