// The geometry a bundle learned at its training resolution (multilayer regions, size filter),
// mapped onto a frame of any size without stretching it.
//
// A camera frame of another size is taken to show the scene with the same horizontal field of
// view and the same camera pitch, principal point at the centre (the usual case for forward
// road cameras: 2048 x 1024 Lost and Found, 1920 x 1080 and 1280 x 720 dash cameras). Pixel
// lengths then scale by one factor s = width / training width, and a row keeps its offset from
// the image centre times s. So a 2048 x 1024 bundle on a 1920 x 1080 frame uses s = 0.9375 and
// shifts rows by +60 px (the taller frame shows more above and below); on 1280 x 720, s = 0.625.
// Regions are clipped to the frame.
//
// A camera mounted higher or lower, or pitched, puts the road elsewhere: self-calibration
// (core/calibration, issue 48) estimates the frame's horizon and moves every row the bundle
// learned by the horizon's offset from the bundle's reference (FrameGeometry::horizon).
#pragma once

#include <opencv2/core.hpp>

#include "core/calibration/horizon_choice.h"
#include "core/features/box_features.h"
#include "core/pipeline/model_bundle.h"

namespace tod {

// x' = s x + dx, y' = s y + dy.
struct FrameMapping {
  double scale = 1.0;
  double dx = 0.0;
  double dy = 0.0;
  Box Map(const Box& b) const;
};

// The mapping from the training frame (train_w x train_h) to a frame of width x height.
FrameMapping MappingForFrame(int train_width, int train_height, int width, int height);

// Regions and size filter of a bundle for frames of a given size, every row moved down by
// horizon_shift rows (the calibrated horizon's offset, HorizonUse::shift).
struct FrameGeometry {
  MultilayerRegions regions;
  SizeFilter size_filter;
  HorizonUse horizon;  // where the rows stand and why; horizon.shift moved them
};
FrameGeometry GeometryForFrame(const ModelBundle& bundle, int width, int height,
                               double horizon_shift = 0);

// How a frame's geometry is chosen: with `calibrate`, from the frame's horizon estimate (and the
// camera's, when `camera` is not null), else the bundle's.
struct GeometryRequest {
  bool calibrate = true;
  CameraTrack* camera = nullptr;
};
FrameGeometry CalibratedGeometryForFrame(const ModelBundle& bundle, const cv::Mat3b& frame,
                                         const GeometryRequest& request);

// The bundle's horizon reference on a frame of width x height; none without one.
std::optional<double> BundleHorizonRow(const ModelBundle& bundle, int width, int height);

// The proposal features' options of a bundle for frames of a given size: the ground-plane
// horizon (PipelineParams::box_features) mapped like the regions' rows.
BoxFeatureOptions FeatureOptionsForFrame(const ModelBundle& bundle, int width, int height,
                                         double horizon_shift = 0);

}  // namespace tod
