// The 20 features of a proposal (ALGORITHM.md §5), computed on one region's occlusion edge map
// (un-normalised) and colour crop. Order is fixed:
//  0 max edge, 1 mode edge, 2 mode proportion, 3 inner mean edge, 4 inner edge density,
//  5 mean edge, 6 edge density, 7 normalised area, 8 aspect ratio, 9 objectness,
//  10 X centre, 11 Y centre, 12 width, 13 height (full-image coordinates / actual image size),
//  14-16 H/S/V standard deviation, 17-19 H/S/V contrast against the surround ring;
//  with BoxFeatureOptions::vertical_edges one more (ours): 20 the vertical edge share
//  (vertical_edges.h); with road_surround one more after those (ours): how unlike the road in front
//  of the car the surround ring is (RoadPatch below).
//
// Cost model (1800 x 620 region): construction is one pass over the edge map (runs of one value
// per row, sparse_edge_map.h: 12 B per run) plus, unless a frame-wide ColourIntegrals is shared,
// one pass over the colour crop (colour_integrals.h: about 25 B/pixel) instead of the former 250
// B/pixel of full-resolution integral images. Per box: features 0-6 scan the runs in the box's
// rows (O(rows + runs in the box)); 14-19 are coarse-grid lookups plus scans of the strips (under
// 4 px wide) around the cell-aligned part. ComputeAll visits the boxes in spatial order so that
// these scans mostly hit the cache.
//
// Everything is exact except one documented approximation, on by default: the colour contrast
// (17-19) of a LARGE box (grown box >= contrast_snap_min_area pixels, i.e. box ~64 x 64 and up,
// box sides >= 8) counts the box and the grown box with their sides moved to the nearest multiple
// of 4 (full-image coordinates; sides on the region border stay put), at most 2 px per side. On a
// smooth random colour image this changed features 17-19 by at most 0.05 (0.013 from 256 x 256 px
// grown boxes, 0.13 if applied from 64 x 64); it saves the strip scans. exact_contrast = true
// turns it off; the exact path reproduces the former full-resolution implementation (features
// 14-16 up to 3e-8).
#pragma once

#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/features/colour_integrals.h"
#include "core/features/hsv.h"  // BgrToHsv, HueBin, SatValBin, kHueBins, kSatValBins, ...
#include "core/features/sparse_edge_map.h"
#include "core/features/vertical_edges.h"

namespace tod {

// The paper's 20 features; a row has one more with each of BoxFeatureOptions::vertical_edges and
// road_surround.
inline constexpr int kNumBoxFeatures = 20;
inline constexpr int kMaxBoxFeatures = kNumBoxFeatures + 2;
// Compute()'s result: the row's NumBoxFeatures(options) entries, the rest 0.
using BoxFeatureVector = std::array<float, kMaxBoxFeatures>;

struct BoxFeatureOptions {
  // ALGORITHM.md §5 "coordinates quirk": the original code computed features 10-11 from
  // region-relative box coordinates. Off by default (full-image coordinates, [R]); the flag
  // exists to reproduce models trained the old way. Features 12-13 do not depend on it, nor does
  // feature 10 with a horizon (full-image columns).
  bool region_relative_centre = false;
  // Colour contrast of large boxes (see the top of this file). exact_contrast = true counts every
  // histogram exactly (slower on large boxes, same values on small ones).
  bool exact_contrast = false;
  int contrast_snap_min_area = 128 * 128;  // grown-box pixels from which snapping applies
  // Features 10, 12, 13 as a physical position and size (PipelineParams::box_features): when
  // set, (centre column − middle column) / d, w / d and h / d with d = box centre row −
  // *horizon_y in full-image pixels, at least 1. Unset: the centre column, w and h over the
  // image's width and height (the paper's).
  std::optional<double> horizon_y = std::nullopt;
  // Feature 21 (index 20), the share of the box's strong gradient on near-vertical edges
  // (vertical_edges.h). Off: the paper's 20 features.
  bool vertical_edges = false;
  // One more feature after those (ours): how unlike the road the box's surround is, the mean
  // over H, S and V of the cosine distance between the histograms of the surround ring of
  // features 18-20 and of the road just in front of the car (RoadPatch of the colour crop: R1's
  // with the shared tables, as the pipeline builds them; the region's own with per-region
  // tables, which is the road in front only for R1). Off: not computed.
  bool road_surround = false;
};

// The road just in front of the car in a colour crop of `crop` pixels whose crop is R1 (or
// holds it): the middle half of its columns in its bottom tenth of rows. Fixed by the regions,
// which are fitted to the training obstacles' rows, not by any frame's content.
cv::Rect RoadPatch(cv::Size crop);

// Columns of a feature row under `options`: 20, plus one for each of vertical_edges and
// road_surround.
inline int NumBoxFeatures(const BoxFeatureOptions& options) {
  return kNumBoxFeatures + (options.vertical_edges ? 1 : 0) + (options.road_surround ? 1 : 0);
}

class BoxFeatureExtractor {
 public:
  // region_map: occlusion edge map of the region crop; region_bgr: colour crop of the same size;
  // region_origin: crop's top-left in the full image; image_size: full frame size.
  // Builds the colour tables (and, with options.vertical_edges, the vertical-edge tables) of this
  // crop itself; prefer the shared form below when several regions of one frame are measured.
  // On invalid input (sizes differ, crop outside the frame, non-finite map values) the extractor
  // is empty, status() says why, and Compute() returns zeros except the objectness.
  BoxFeatureExtractor(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                      cv::Point region_origin, cv::Size image_size,
                      const BoxFeatureOptions& options = {});

  // Shares the colour tables of a larger crop (normally R1) that contains this region, so a
  // frame converts and integrates its colours once for all its regions. frame_colour->origin()
  // locates that crop in the full image; the region [region_origin, + region_map.size()) must lie
  // inside it. The surround ring of features 17-19 is still clipped to this region. Gives the
  // same features as the constructor above on the same region (up to double rounding in 14-16).
  // With options.vertical_edges, frame_vertical holds the vertical-edge tables of the same larger
  // crop (required; feature 21 then differs from the per-region form only in the region's border
  // pixels, where the per-region tables reflect the crop instead of reading the frame).
  BoxFeatureExtractor(std::shared_ptr<const ColourIntegrals> frame_colour,
                      const cv::Mat1f& region_map, cv::Point region_origin, cv::Size image_size,
                      const BoxFeatureOptions& options = {},
                      std::shared_ptr<const VerticalEdgeIntegrals> frame_vertical = nullptr);

  // Same as the constructors, but invalid input is an error instead of an empty extractor.
  static Result<BoxFeatureExtractor> Create(const cv::Mat1f& region_map,
                                            const cv::Mat3b& region_bgr, cv::Point region_origin,
                                            cv::Size image_size,
                                            const BoxFeatureOptions& options = {});
  static Result<BoxFeatureExtractor> Create(
      std::shared_ptr<const ColourIntegrals> frame_colour, const cv::Mat1f& region_map,
      cv::Point region_origin, cv::Size image_size, const BoxFeatureOptions& options = {},
      std::shared_ptr<const VerticalEdgeIntegrals> frame_vertical = nullptr);

  const Status& status() const { return status_; }

  // box: full-image coordinates; clipped to the region first. objectness: the OLP score.
  BoxFeatureVector Compute(const Box& box, float objectness) const;

  // One row of NumBoxFeatures(options) features per proposal (box + OLP score), in input order;
  // thread-safe.
  cv::Mat1f ComputeAll(const std::vector<ScoredBox>& proposals) const;
  // As ComputeAll, but the features of proposals[j] go to row out_rows[j] of `out`
  // (NumBoxFeatures(options) columns, every out_rows[j] a row of it): a caller that merges several
  // regions' proposals into one matrix writes each row once instead of copying it over.
  void ComputeInto(const std::vector<ScoredBox>& proposals, const std::vector<int>& out_rows,
                   cv::Mat1f& out) const;

 private:
  // Validates, then builds the sparse edge map; leaves the extractor empty on error.
  void Init(const cv::Mat1f& region_map);
  // Compute's steps for the box `r`, clipped to the region, in region-local coordinates.
  void AddEdgeFeatures(const cv::Rect& r, BoxFeatureVector& f) const;      // 1-7
  void AddPlaceFeatures(const cv::Rect& r, BoxFeatureVector& f) const;     // 8, 9, 11-14
  void AddColourSpread(const cv::Rect& r, BoxFeatureVector& f) const;      // 15-17
  void AddEdgeOrientation(const cv::Rect& r, BoxFeatureVector& f) const;   // 21
  void AddSurroundContrast(const cv::Rect& r, BoxFeatureVector& f) const;  // 18-20 (and road)

  Status status_;
  BoxFeatureOptions options_;
  cv::Size region_size_;  // (0, 0) when empty: every box then misses the region
  cv::Point origin_;
  cv::Size image_size_;
  SparseEdgeMap edges_;
  std::shared_ptr<const ColourIntegrals> colour_;
  cv::Rect region_in_colour_;    // the region in colour_'s crop coordinates
  ColourHistogram road_hist_{};  // RoadPatch of colour_'s crop, with options_.road_surround
  // null unless options_.vertical_edges
  std::shared_ptr<const VerticalEdgeIntegrals> vertical_;
  cv::Point region_in_vertical_;  // the region's corner in vertical_'s crop
};

}  // namespace tod
