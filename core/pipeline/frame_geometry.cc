#include "core/pipeline/frame_geometry.h"

#include <algorithm>
#include <cmath>

namespace tod {

Box FrameMapping::Map(const Box& b) const {
  const int x0 = static_cast<int>(std::floor(b.x * scale + dx));
  const int y0 = static_cast<int>(std::floor(b.y * scale + dy));
  const int x1 = static_cast<int>(std::ceil(b.right() * scale + dx));
  const int y1 = static_cast<int>(std::ceil(b.bottom() * scale + dy));
  return {x0, y0, x1 - x0, y1 - y0};
}

FrameMapping MappingForFrame(int train_width, int train_height, int width, int height) {
  FrameMapping m;
  if (train_width <= 0 || train_height <= 0) return m;
  m.scale = static_cast<double>(width) / train_width;
  m.dx = 0.5 * width - m.scale * 0.5 * train_width;  // 0: the widths match by construction
  m.dy = 0.5 * height - m.scale * 0.5 * train_height;
  return m;
}

FrameGeometry GeometryForFrame(const ModelBundle& bundle, int width, int height,
                               double horizon_shift) {
  FrameGeometry g;
  g.size_filter = bundle.size_filter;
  g.horizon.row = BundleHorizonRow(bundle, width, height);
  g.horizon.bundle_row = g.horizon.row;
  const MultilayerRegions& trained = bundle.regions;
  if (width == trained.image_width && height == trained.image_height && horizon_shift == 0) {
    g.regions = trained;
    return g;
  }
  FrameMapping m = MappingForFrame(trained.image_width, trained.image_height, width, height);
  m.dy += horizon_shift;
  g.regions.image_width = width;
  g.regions.image_height = height;
  for (const Box& r : trained.layers)
    g.regions.layers.push_back(ClipToImage(m.Map(r), width, height));
  const double s = m.scale;
  for (SizeBand& b : g.size_filter.bands) {
    b.center_y_min = b.center_y_min * s + m.dy;
    b.center_y_max = b.center_y_max * s + m.dy;
    b.h_min *= s, b.h_max *= s;
    b.w_min *= s, b.w_max *= s;
    b.area_min *= s * s, b.area_max *= s * s;
  }
  return g;
}

namespace {

// A training-frame row of the bundle on a frame of width x height.
double MappedRow(const ModelBundle& bundle, int width, int height, double row) {
  const MultilayerRegions& trained = bundle.regions;
  const FrameMapping m = MappingForFrame(trained.image_width, trained.image_height, width, height);
  return row * m.scale + m.dy;
}

}  // namespace

std::optional<double> BundleHorizonRow(const ModelBundle& bundle, int width, int height) {
  if (!bundle.horizon_reference) return std::nullopt;
  return MappedRow(bundle, width, height, bundle.horizon_reference->row);
}

FrameGeometry CalibratedGeometryForFrame(const ModelBundle& bundle, const cv::Mat3b& frame,
                                         const GeometryRequest& request) {
  if (!request.calibrate) {
    FrameGeometry g = GeometryForFrame(bundle, frame.cols, frame.rows);
    g.horizon.fallback = "calibration off";
    return g;
  }
  const std::optional<double> bundle_row = BundleHorizonRow(bundle, frame.cols, frame.rows);
  // A bundle without a reference cannot be moved: the frame is not even looked at.
  const HorizonEstimate estimate = bundle_row ? EstimateHorizon(frame) : HorizonEstimate{};
  HorizonUse use = ChooseHorizon(bundle_row, frame.rows, estimate, request.camera);
  FrameGeometry g = GeometryForFrame(bundle, frame.cols, frame.rows, use.shift);
  g.horizon = std::move(use);
  return g;
}

BoxFeatureOptions FeatureOptionsForFrame(const ModelBundle& bundle, int width, int height,
                                         double horizon_shift) {
  BoxFeatureOptions options;
  options.vertical_edges = bundle.params.vertical_edge_feature;
  options.road_surround = bundle.params.road_surround_feature;
  const GroundPlaneFeatureParams& params = bundle.params.box_features;
  if (params.ground_plane_size)
    options.horizon_y = MappedRow(bundle, width, height, params.horizon_y) + horizon_shift;
  return options;
}

}  // namespace tod
