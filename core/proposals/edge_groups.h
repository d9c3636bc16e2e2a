// Edge groups of an OLP edge map and their affinities (ALGORITHM.md §4.2 steps 1-3): the unit
// Edge Boxes reasons about. Built once per region map; every window score reads these tables.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace tod {

struct EdgeGroupParams {
  float edge_min_mag = 0.1f;     // pixels with M > this are edge pixels
  float edge_merge_thr = 0.5f;   // the greedy walk stops when its accumulated cost reaches this
  float cluster_min_mag = 0.5f;  // groups with magnitude sum <= this are dissolved
  float gamma = 2.f;             // affinity exponent
};

// The edge pixels (M > a threshold) of a map in both scan orders, with their values, found in one
// pass. Edge pixels are a few % of an OLP map, so every per-map table that only changes at edge
// pixels (grouping, statistics, integral images, run indexes) is built from these lists instead
// of from full passes over the map.
struct EdgePixels {
  int rows = 0, cols = 0;
  // Row r holds entries [row_begin[r], row_begin[r + 1]): columns row_col[i] (ascending), values
  // row_value[i]. Size rows + 1.
  std::vector<int> row_begin;
  std::vector<int> row_col;
  std::vector<float> row_value;
  // Column c holds entries [col_begin[c], col_begin[c + 1]): rows col_row[i] (ascending), values
  // col_value[i]. Size cols + 1.
  std::vector<int> col_begin;
  std::vector<int> col_row;
  std::vector<float> col_value;
};

// Pixels with map > min_magnitude (NaN never is).
EdgePixels FindEdgePixels(const cv::Mat1f& map, float min_magnitude);

// Group ids are 1..count(); id 0 means "no group" (not an edge pixel, the 1-pixel map border, or
// a dissolved pixel with no grouped neighbour). Index 0 of every per-group vector is unused.
struct EdgeGroups {
  cv::Mat1i ids;                   // per-pixel group id
  std::vector<float> magnitude;    // m_s: sum of M over the group's pixels
  std::vector<float> mean_x;       // magnitude-weighted mean column
  std::vector<float> mean_y;       // magnitude-weighted mean row
  std::vector<float> orientation;  // doubled-angle mean of theta, in (-pi/2, pi/2]
  std::vector<int> anchor_x;       // last pixel of the group in column-major order: decides
  std::vector<int> anchor_y;       //   whether the group counts as inside a box
  // Affinity graph in compressed rows: neighbours of s are
  // affinity_target[affinity_begin[s] .. affinity_begin[s + 1]), weights in affinity_value.
  std::vector<int> affinity_begin;
  std::vector<int> affinity_target;
  std::vector<float> affinity_value;
  // The map's edge pixels (M > edge_min_mag) the groups were built from; every grouped pixel is
  // one of them (border pixels and dissolved pixels without a grouped neighbour have id 0).
  EdgePixels edges;

  int count() const { return magnitude.empty() ? 0 : static_cast<int>(magnitude.size()) - 1; }
};

// Step 1 only: greedy column-major grouping with the persistent candidate list, dissolution of
// weak groups and compact relabelling. Returns the id map (0 = no group). Exposed for tests.
cv::Mat1i GroupEdgePixels(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                          const EdgeGroupParams& params);

// Steps 1-3: ids, statistics, anchors and affinities a(s,t) = |cos(th_s - phi) cos(th_t - phi)|^g
// for groups that come within a 5x5 neighbourhood of each other. Maps must have equal size.
EdgeGroups BuildEdgeGroups(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                           const EdgeGroupParams& params);
// The same with the orientation of ComputeEdgeOrientation(edge_map) computed here, at the edge
// pixels only (the only pixels grouping reads it at); bit-identical result.
EdgeGroups BuildEdgeGroups(const cv::Mat1f& edge_map, const EdgeGroupParams& params);

}  // namespace tod
