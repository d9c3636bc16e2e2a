// The 20 features of a frame's proposals (§5), and with BoxFeatureOptions::vertical_edges the
// 21st, each computed on the region that produced it.
#pragma once

#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/box_features.h"
#include "core/pipeline/multilayer_regions.h"

namespace tod {

struct OcclusionEdges;
struct ProposalSet;
class ColourIntegrals;
class VerticalEdgeIntegrals;

// R1's colour tables, shared by every region's features: the colour integrals (features 15-20)
// and, when the options ask for them, the vertical edge integrals (21-22). They read the image
// alone, so a detector with threads to spare builds them beside the regions' merge.
struct FrameColourTables {
  std::shared_ptr<const ColourIntegrals> colour;
  std::shared_ptr<const VerticalEdgeIntegrals> vertical;  // null when the options need none
};

// The tables of the crop `r1` (full-image box) of `image`, on OpenCV's pool (cv::setNumThreads);
// the same tables for any thread count.
FrameColourTables BuildFrameColourTables(const cv::Mat3b& image, const Box& r1,
                                         const BoxFeatureOptions& options);

// Computes the feature rows of any range of a frame's proposals: the colour integrals of R1
// (shared by every region, the regions being nested crops of R1) and each region's edge tables
// are built once, so a frame's proposals can be measured in chunks (the frame budget regresses
// them in objectness order until its deadline) or by several threads at once (ComputeRange is
// const and thread-safe).
class ProposalFeatureComputer {
 public:
  // Keeps references to all three arguments: they must outlive the computer. The tables are
  // built on up to `threads` threads (the regions' edge tables side by side; the colour tables
  // on OpenCV's pool, cv::setNumThreads), the same for any count. `colour`: R1's tables built
  // beforehand (BuildFrameColourTables with the same image and options); empty, they are built
  // here.
  ProposalFeatureComputer(const cv::Mat3b& image, const OcclusionEdges& oaocc,
                          const MultilayerRegions& regions, const ProposalSet& proposals,
                          const BoxFeatureOptions& options, int threads = 1,
                          FrameColourTables colour = {});
  // Rows [begin, end) of `out` (proposals x NumBoxFeatures(options)) for proposals [begin, end).
  void ComputeRange(std::size_t begin, std::size_t end, cv::Mat1f& out) const;

 private:
  const ProposalSet& proposals_;
  std::vector<std::unique_ptr<const BoxFeatureExtractor>> per_region_;  // null: no proposal
};

// One row of NumBoxFeatures(options) features per proposal.
cv::Mat1f ComputeProposalFeatures(const cv::Mat3b& image, const OcclusionEdges& oaocc,
                                  const MultilayerRegions& regions, const ProposalSet& proposals,
                                  const BoxFeatureOptions& options);

}  // namespace tod
