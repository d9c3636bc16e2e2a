// Label-map post-processing for the sticky superpixels (ALGORITHM.md §3.2(1), last two bullets):
// consecutive relabelling of connected components and insertion of the 1-pixel boundary label 0.
#pragma once

#include <opencv2/core.hpp>

namespace tod {

// Relabels the 4-connected components of `labels` (any non-negative ids) to 1..count in raster
// order of first appearance. Returns count.
int RelabelConnectedComponents(cv::Mat1i& labels);

// Inserts label-0 boundaries between different labels, guided by the edge map (same size):
//  1. of every 4-adjacent pair with different labels, the pixel with the larger edge value
//     becomes boundary;
//  2. a pixel with a different (non-zero) label in its 8-neighbourhood becomes boundary unless all
//     of its 4-neighbours carry its own label;
//  3. thinning, in raster order: a boundary pixel whose labelled 8-neighbours all share one label
//     returns to that label.
// Afterwards no two different non-zero labels are 8-adjacent.
void InsertSuperpixelBoundaries(const cv::Mat1f& edge, cv::Mat1i& labels);

// Maps the non-zero labels present to 1..count keeping their order; 0 stays 0. Returns count.
int CompactLabels(cv::Mat1i& labels);

}  // namespace tod
