#include "core/pipeline/proposal_features.h"

#include <stdexcept>

#include "core/features/colour_integrals.h"
#include "core/features/vertical_edges.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/parallel.h"

namespace tod {

FrameColourTables BuildFrameColourTables(const cv::Mat3b& image, const Box& r1,
                                         const BoxFeatureOptions& options) {
  const cv::Mat3b r1_bgr = image(r1.rect());
  const cv::Point r1_origin(r1.x, r1.y);
  FrameColourTables tables;
  tables.colour = std::make_shared<const ColourIntegrals>(r1_bgr, r1_origin);
  if (options.vertical_edges)
    tables.vertical = std::make_shared<const VerticalEdgeIntegrals>(r1_bgr, r1_origin);
  return tables;
}

ProposalFeatureComputer::ProposalFeatureComputer(const cv::Mat3b& image,
                                                 const OcclusionEdges& oaocc,
                                                 const MultilayerRegions& regions,
                                                 const ProposalSet& proposals,
                                                 const BoxFeatureOptions& options, int threads,
                                                 FrameColourTables colour)
    : proposals_(proposals), per_region_(regions.num_layers()) {
  if (proposals.boxes.empty()) return;
  std::vector<bool> used(regions.num_layers(), false);
  for (const int k : proposals.layer) used[k] = true;
  if (colour.colour == nullptr) colour = BuildFrameColourTables(image, oaocc.r1, options);
  const std::shared_ptr<const ColourIntegrals>& frame_colour = colour.colour;
  const std::shared_ptr<const VerticalEdgeIntegrals>& frame_vertical = colour.vertical;
  // Each region's edge tables are one pass over its map, independent of the others.
  for (const Status& s : ParallelFor(regions.num_layers(), threads, [&](int k) {
         if (!used[k]) return Status::Ok();
         const Box region = Intersect(regions.layers[k], oaocc.r1);
         per_region_[k] = std::make_unique<const BoxFeatureExtractor>(
             frame_colour, RegionEdgeMap(oaocc, regions, k), cv::Point(region.x, region.y),
             image.size(), options, frame_vertical);
         return Status::Ok();
       }))
    if (!s.ok()) throw std::runtime_error(s.ToString());
}

void ProposalFeatureComputer::ComputeRange(std::size_t begin, std::size_t end,
                                           cv::Mat1f& out) const {
  // Grouped by region, each region's rows go straight to their place in `out`. The lists are
  // sized for the whole range once: growing them from empty took the shared heap's lock a dozen
  // times per range while the other thread of the request did the same.
  const std::size_t range = end > begin ? end - begin : 0;
  for (std::size_t k = 0; k < per_region_.size(); ++k) {
    if (!per_region_[k]) continue;
    std::vector<int> rows;
    std::vector<ScoredBox> boxes;
    rows.reserve(range);
    boxes.reserve(range);
    for (std::size_t i = begin; i < end && i < proposals_.boxes.size(); ++i)
      if (proposals_.layer[i] == static_cast<int>(k)) {
        rows.push_back(static_cast<int>(i));
        boxes.push_back(proposals_.boxes[i]);
      }
    if (!rows.empty()) per_region_[k]->ComputeInto(boxes, rows, out);
  }
}

cv::Mat1f ComputeProposalFeatures(const cv::Mat3b& image, const OcclusionEdges& oaocc,
                                  const MultilayerRegions& regions, const ProposalSet& proposals,
                                  const BoxFeatureOptions& options) {
  cv::Mat1f rows(static_cast<int>(proposals.boxes.size()), NumBoxFeatures(options), 0.f);
  ProposalFeatureComputer(image, oaocc, regions, proposals, options)
      .ComputeRange(0, proposals.boxes.size(), rows);
  return rows;
}

}  // namespace tod
