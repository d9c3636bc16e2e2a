#include "core/features/box_features.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace tod {
namespace {

std::string SizeText(const cv::Size& s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

std::string PlaceText(const cv::Size& s, cv::Point at) {
  return SizeText(s) + " at (" + std::to_string(at.x) + ", " + std::to_string(at.y) + ")";
}

// The region crop must lie inside a frame of positive size.
Status ValidateGeometry(cv::Size region_size, cv::Point region_origin, cv::Size image_size) {
  if (image_size.width <= 0 || image_size.height <= 0) {
    return Status::InvalidArgument("BoxFeatureExtractor: image_size " + SizeText(image_size) +
                                   " must be positive");
  }
  if (region_origin.x < 0 || region_origin.y < 0 ||
      region_origin.x + region_size.width > image_size.width ||
      region_origin.y + region_size.height > image_size.height) {
    return Status::InvalidArgument(
        "BoxFeatureExtractor: region crop " + PlaceText(region_size, region_origin) +
        " does not lie inside the image of size " + SizeText(image_size));
  }
  return Status::Ok();
}

Status ValidateInput(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                     cv::Point region_origin, cv::Size image_size) {
  if (region_map.size() != region_bgr.size()) {
    return Status::InvalidArgument("BoxFeatureExtractor: region_map is " +
                                   SizeText(region_map.size()) + " but region_bgr is " +
                                   SizeText(region_bgr.size()) + "; they must match");
  }
  return ValidateGeometry(region_map.size(), region_origin, image_size);
}

// The region [region_origin, + region_size) must lie inside a shared table's crop.
Status RegionInsideCrop(cv::Size region_size, cv::Point region_origin, cv::Size crop_size,
                        cv::Point crop_origin, const char* table) {
  const cv::Rect region(region_origin, region_size);
  if ((region & cv::Rect(crop_origin, crop_size)) == region) return Status::Ok();
  return Status::InvalidArgument(
      "BoxFeatureExtractor: region_map " + PlaceText(region_size, region_origin) +
      " does not lie inside the " + table + " crop " + PlaceText(crop_size, crop_origin));
}

Status ValidateShared(const ColourIntegrals* frame_colour, const cv::Mat1f& region_map,
                      cv::Point region_origin, cv::Size image_size) {
  if (frame_colour == nullptr) {
    return Status::InvalidArgument("BoxFeatureExtractor: frame_colour is null");
  }
  if (Status geometry = ValidateGeometry(region_map.size(), region_origin, image_size);
      !geometry.ok()) {
    return geometry;
  }
  return RegionInsideCrop(region_map.size(), region_origin, frame_colour->size(),
                          frame_colour->origin(), "frame_colour");
}

Status ValidateVertical(const VerticalEdgeIntegrals* frame_vertical,
                        const BoxFeatureOptions& options, const cv::Mat1f& region_map,
                        cv::Point region_origin) {
  if (!options.vertical_edges) return Status::Ok();
  if (frame_vertical == nullptr) {
    return Status::InvalidArgument(
        "BoxFeatureExtractor: options.vertical_edges needs the frame's vertical-edge tables "
        "(frame_vertical is null)");
  }
  return RegionInsideCrop(region_map.size(), region_origin, frame_vertical->size(),
                          frame_vertical->origin(), "frame_vertical");
}

// Sort key of a box for ComputeAll: tiles of 64 x 64 pixels (by the box centre) in row-major
// order, then the centre's y and x.
std::int64_t SpatialKey(const Box& b) {
  const std::int64_t cx = b.x + b.w / 2, cy = b.y + b.h / 2;
  return (((cy >> 6) << 20) + (cx >> 6)) * (std::int64_t{1} << 24) + (cy & 63) * 64 + (cx & 63);
}

double SafeDiv(double num, double den) { return den != 0.0 ? num / den : 0.0; }

// 1 - a.b / (|a||b|) over one channel's 16 bins; 0 when either histogram is all zero (the
// original gives NaN there, which [C-ROS] replaces by 0).
float CosineDistance(const int* a, const int* b, int bins) {
  double dot = 0.0, norm_a = 0.0, norm_b = 0.0;
  for (int i = 0; i < bins; ++i) {
    dot += static_cast<double>(a[i]) * b[i];
    norm_a += static_cast<double>(a[i]) * a[i];
    norm_b += static_cast<double>(b[i]) * b[i];
  }
  if (norm_a <= 0.0 || norm_b <= 0.0) return 0.f;
  return static_cast<float>(1.0 - dot / std::sqrt(norm_a * norm_b));
}

// Cosine distances between the H, S and V parts of two histograms (hsv.h's layout).
std::array<float, 3> HsvCosineDistances(const ColourHistogram& a, const ColourHistogram& b) {
  return {CosineDistance(a.data(), b.data(), kHueBins),
          CosineDistance(a.data() + kHueBins, b.data() + kHueBins, kSatValBins),
          CosineDistance(a.data() + kHueBins + kSatValBins, b.data() + kHueBins + kSatValBins,
                         kSatValBins)};
}

}  // namespace

cv::Rect RoadPatch(cv::Size crop) {
  const int rows = std::max(1, crop.height / 10);
  const int cols = std::max(1, crop.width / 2);
  return cv::Rect((crop.width - cols) / 2, crop.height - rows, cols, rows) &
         cv::Rect(cv::Point(0, 0), crop);
}

BoxFeatureExtractor::BoxFeatureExtractor(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                                         cv::Point region_origin, cv::Size image_size,
                                         const BoxFeatureOptions& options)
    : status_(ValidateInput(region_map, region_bgr, region_origin, image_size)),
      options_(options),
      origin_(region_origin),
      image_size_(image_size) {
  if (!status_.ok()) return;
  Init(region_map);
  if (!status_.ok()) return;
  colour_ = std::make_shared<const ColourIntegrals>(region_bgr, region_origin);
  region_in_colour_ = cv::Rect(cv::Point(0, 0), region_map.size());
  if (options_.road_surround) road_hist_ = colour_->Histogram(RoadPatch(colour_->size()));
  if (options_.vertical_edges)
    vertical_ = std::make_shared<const VerticalEdgeIntegrals>(region_bgr, region_origin);
}

BoxFeatureExtractor::BoxFeatureExtractor(
    std::shared_ptr<const ColourIntegrals> frame_colour, const cv::Mat1f& region_map,
    cv::Point region_origin, cv::Size image_size, const BoxFeatureOptions& options,
    std::shared_ptr<const VerticalEdgeIntegrals> frame_vertical)
    : status_(ValidateShared(frame_colour.get(), region_map, region_origin, image_size)),
      options_(options),
      origin_(region_origin),
      image_size_(image_size) {
  if (status_.ok())
    status_ = ValidateVertical(frame_vertical.get(), options, region_map, region_origin);
  if (!status_.ok()) return;
  Init(region_map);
  if (!status_.ok()) return;
  region_in_colour_ = cv::Rect(region_origin - frame_colour->origin(), region_map.size());
  colour_ = std::move(frame_colour);
  if (options_.road_surround) road_hist_ = colour_->Histogram(RoadPatch(colour_->size()));
  if (options_.vertical_edges) {
    region_in_vertical_ = region_origin - frame_vertical->origin();
    vertical_ = std::move(frame_vertical);
  }
}

void BoxFeatureExtractor::Init(const cv::Mat1f& region_map) {
  Result<SparseEdgeMap> edges = SparseEdgeMap::Build(region_map);
  if (!edges.ok()) {
    status_ = edges.status();
    return;
  }
  edges_ = std::move(edges).value();
  region_size_ = region_map.size();
}

Result<BoxFeatureExtractor> BoxFeatureExtractor::Create(const cv::Mat1f& region_map,
                                                        const cv::Mat3b& region_bgr,
                                                        cv::Point region_origin,
                                                        cv::Size image_size,
                                                        const BoxFeatureOptions& options) {
  BoxFeatureExtractor extractor(region_map, region_bgr, region_origin, image_size, options);
  if (!extractor.status().ok()) return extractor.status();
  return extractor;
}

Result<BoxFeatureExtractor> BoxFeatureExtractor::Create(
    std::shared_ptr<const ColourIntegrals> frame_colour, const cv::Mat1f& region_map,
    cv::Point region_origin, cv::Size image_size, const BoxFeatureOptions& options,
    std::shared_ptr<const VerticalEdgeIntegrals> frame_vertical) {
  BoxFeatureExtractor extractor(std::move(frame_colour), region_map, region_origin, image_size,
                                options, std::move(frame_vertical));
  if (!extractor.status().ok()) return extractor.status();
  return extractor;
}

BoxFeatureVector BoxFeatureExtractor::Compute(const Box& box, float objectness) const {
  BoxFeatureVector f{};
  f[9] = objectness;
  // Clip to the region crop, in region-local coordinates (ALGORITHM.md §5: "the box is first
  // clipped to the region"). No overlap: nothing to measure.
  const Box local_box = ClipToImage(Box{box.x - origin_.x, box.y - origin_.y, box.w, box.h},
                                    region_size_.width, region_size_.height);
  if (local_box.empty()) return f;
  const cv::Rect r = local_box.rect();
  AddEdgeFeatures(r, f);
  AddPlaceFeatures(r, f);
  AddColourSpread(r, f);
  AddEdgeOrientation(r, f);
  AddSurroundContrast(r, f);
  return f;
}

// Features 1-7. Features 4-5 use the centre sub-box (half width, half height, same centre; the
// code's "inner ring", ALGORITHM.md §10 #10), normalised by A/4 as in the original.
void BoxFeatureExtractor::AddEdgeFeatures(const cv::Rect& r, BoxFeatureVector& f) const {
  const int w = r.width, h = r.height;
  const double area = static_cast<double>(w) * h;
  const int inner_w = w / 2, inner_h = h / 2;
  const cv::Rect inner(r.x + (w - inner_w) / 2, r.y + (h - inner_h) / 2, inner_w, inner_h);
  const BoxEdgeStats edges = edges_.Measure(r, inner);
  f[0] = edges.max_value;
  f[1] = edges.mode_value;
  f[2] = static_cast<float>(SafeDiv(edges.mode_count, edges.count));
  f[3] = static_cast<float>(SafeDiv(edges.inner_sum, area / 4.0));
  f[4] = static_cast<float>(SafeDiv(edges.inner_count, area / 4.0));
  f[5] = static_cast<float>(edges.sum / area);
  f[6] = static_cast<float>(edges.count / area);
}

// Features 8-9, 11-14: pseudodistance, normalised by the actual image size (§10 #23).
void BoxFeatureExtractor::AddPlaceFeatures(const cv::Rect& r, BoxFeatureVector& f) const {
  const int w = r.width, h = r.height;
  const double area = static_cast<double>(w) * h;
  const double image_w = image_size_.width, image_h = image_size_.height;
  const int x_for_centre = options_.region_relative_centre ? r.x : r.x + origin_.x;
  const int y_for_centre = options_.region_relative_centre ? r.y : r.y + origin_.y;
  f[7] = static_cast<float>(area / (image_w * image_h));
  f[8] = static_cast<float>(static_cast<double>(w) / h);
  f[11] = static_cast<float>((y_for_centre + h / 2.0) / image_h);
  if (options_.horizon_y) {
    // On a flat road, image lengths at d rows below the horizon are physical lengths times d
    // (over the camera height): the centre's offset from the middle column (the principal point,
    // as frame_geometry.h assumes) over d is how far to the side the box stands, and w / d, h / d
    // its physical size, the same at every distance.
    const double below_horizon =
        std::max(1.0, origin_.y + r.y + h / 2.0 - *options_.horizon_y);  // full-image rows
    f[10] = static_cast<float>((origin_.x + r.x + w / 2.0 - image_w / 2.0) / below_horizon);
    f[12] = static_cast<float>(w / below_horizon);
    f[13] = static_cast<float>(h / below_horizon);
  } else {
    f[10] = static_cast<float>((x_for_centre + w / 2.0) / image_w);
    f[12] = static_cast<float>(w / image_w);
    f[13] = static_cast<float>(h / image_h);
  }
}

// Features 15-17: population standard deviation of H, S, V.
void BoxFeatureExtractor::AddColourSpread(const cv::Rect& r, BoxFeatureVector& f) const {
  const double area = static_cast<double>(r.width) * r.height;
  const ColourMoments moments =
      colour_->Moments(cv::Rect(r.tl() + region_in_colour_.tl(), r.size()));
  for (int c = 0; c < 3; ++c) {
    const double mean = moments[c] / area;
    const double variance = moments[3 + c] / area - mean * mean;
    f[14 + c] = static_cast<float>(std::sqrt(std::max(0.0, variance)));
  }
}

// The optional feature after the paper's 20: the share of strong gradient on near-vertical edges.
void BoxFeatureExtractor::AddEdgeOrientation(const cv::Rect& r, BoxFeatureVector& f) const {
  const cv::Rect box_in_vertical(r.tl() + region_in_vertical_, r.size());
  if (options_.vertical_edges) f[20] = static_cast<float>(vertical_->Share(box_in_vertical));
}

// Features 18-20: histogram of the box against its surround ring = (box grown by w/2 left and
// right, h/2 top and bottom, clipped to the region) minus the box.
void BoxFeatureExtractor::AddSurroundContrast(const cv::Rect& r, BoxFeatureVector& f) const {
  const int w = r.width, h = r.height;
  const int grow_x = w / 2, grow_y = h / 2;
  const Box grown = ClipToImage(Box{r.x - grow_x, r.y - grow_y, w + 2 * grow_x, h + 2 * grow_y},
                                region_size_.width, region_size_.height);
  const cv::Point to_colour = region_in_colour_.tl();
  cv::Rect box_in_colour(r.tl() + to_colour, r.size());
  cv::Rect grown_in_colour(grown.rect().tl() + to_colour, grown.rect().size());
  // The documented approximation for large boxes (header): snap both to the cell grid. Sides of
  // at least two cells keep the snapped box non-empty; snapping is monotone, so the snapped grown
  // box still contains the snapped box and the ring counts stay non-negative.
  if (!options_.exact_contrast && grown.area() >= options_.contrast_snap_min_area &&
      std::min(w, h) >= 2 * kColourCellSize) {
    box_in_colour = colour_->SnapToGrid(box_in_colour, region_in_colour_);
    grown_in_colour = colour_->SnapToGrid(grown_in_colour, region_in_colour_);
  }
  const ColourHistogram box_hist = colour_->Histogram(box_in_colour);
  ColourHistogram ring_hist = colour_->Histogram(grown_in_colour);
  for (int bin = 0; bin < kColourHistBins; ++bin) ring_hist[bin] -= box_hist[bin];
  const std::array<float, 3> contrast = HsvCosineDistances(box_hist, ring_hist);
  std::copy(contrast.begin(), contrast.end(), f.begin() + 17);
  if (options_.road_surround) {
    const int index = kNumBoxFeatures + (options_.vertical_edges ? 1 : 0);
    const std::array<float, 3> unlike_road = HsvCosineDistances(ring_hist, road_hist_);
    f[index] = (unlike_road[0] + unlike_road[1] + unlike_road[2]) / 3.f;
  }
}

cv::Mat1f BoxFeatureExtractor::ComputeAll(const std::vector<ScoredBox>& proposals) const {
  cv::Mat1f features(static_cast<int>(proposals.size()), NumBoxFeatures(options_));
  std::vector<int> rows(proposals.size());
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = static_cast<int>(i);
  ComputeInto(proposals, rows, features);
  return features;
}

void BoxFeatureExtractor::ComputeInto(const std::vector<ScoredBox>& proposals,
                                      const std::vector<int>& out_rows, cv::Mat1f& out) const {
  // Visit the boxes in a spatial order (proposals arrive by objectness, i.e. scattered over the
  // region): consecutive boxes then read the same rows of the edge runs and colour tables, which
  // stay in cache. Compute() depends on its box only and each result goes to its own row, so
  // the output is the same as in input order.
  std::vector<std::pair<std::int64_t, int>> order(proposals.size());
  for (std::size_t i = 0; i < proposals.size(); ++i) {
    const Box& b = proposals[i].box;
    order[i] = {SpatialKey(b), static_cast<int>(i)};
  }
  std::sort(order.begin(), order.end());
  const int columns = NumBoxFeatures(options_);
  CV_Assert(out.cols == columns);
  for (const auto& [key, i] : order) {
    const BoxFeatureVector f = Compute(proposals[i].box, proposals[i].score);
    std::copy(f.begin(), f.begin() + columns, out[out_rows[i]]);
  }
}

}  // namespace tod
