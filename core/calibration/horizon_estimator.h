// The horizon row of a road camera, estimated from one frame with no labels (issue 48).
//
// For a camera with no roll, every family of parallel horizontal world lines (the road's edges,
// lane markings, kerbs, the top and bottom of facades and parked cars) meets at a vanishing
// point on one image row: the horizon. Line segments are found (LSD) on a reduced frame; every
// pair of oblique segments whose lines meet beyond both segments votes for the row where they
// meet, weighted by both lengths and by how well the meeting point is defined (the sine of the
// angle between them). The densest row is the horizon; a frame where too few pairs agree on it
// (a blank wall, fog, a frame of sky) has no estimate, and the caller falls back to the bundle.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace tod {

struct HorizonParams {
  int working_width = 1024;         // the frame is reduced to this width (never enlarged)
  double min_length_frac = 0.02;    // segments shorter than this share of the width are dropped
  double min_angle_deg = 8.0;       // near-horizontal segments define no vanishing point
  double max_angle_deg = 80.0;      // near-vertical ones (poles, walls) meet far off the horizon
  int max_segments = 300;           // the longest ones vote (pairs grow with the square)
  double search_above_frac = 0.5;   // rows searched: from this share of the height above the top
  double search_below_frac = 0.85;  // ... down to this share of the height
  double vote_sigma_px = 2.0;       // the votes' Gaussian width, working pixels
  // An estimate needs this share of the vote mass within 3 sigma of the peak row, and at least
  // min_pairs voting pairs there: else the frame has no estimate.
  double min_peak_share = 0.16;
  int min_pairs = 12;
};

struct HorizonEstimate {
  bool found = false;
  double row = 0;         // full-frame image row (fractional; may be above the frame)
  double peak_share = 0;  // share of the vote mass at the peak row
  int segments = 0;       // oblique segments that voted
  int peak_pairs = 0;     // pairs whose meeting row is at the peak
  std::string reason;     // why none was found (empty when found)
};

HorizonEstimate EstimateHorizon(const cv::Mat3b& bgr, const HorizonParams& params = {});

}  // namespace tod
