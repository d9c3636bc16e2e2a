#include "core/evaluation/stage_images.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/base/atomic_file.h"
#include "core/pipeline/detection_output.h"
#include "core/pipeline/frame_stages.h"

namespace tod {
namespace {

// Line width and font size grow with the frame, so that the drawings stay legible when a
// 2048-pixel frame is viewed scaled down to a screen.
struct Pen {
  int thickness = 1;
  double font_scale = 0.4;
};

Pen PenFor(const cv::Size& frame) {
  return {std::max(1, static_cast<int>(std::lround(frame.width / 1024.0))),
          std::max(0.4, 0.9 * frame.width / 2048.0)};
}

// One colour per region (BGR), cycled beyond six layers.
cv::Scalar RegionColour(int k) {
  static const std::array<cv::Scalar, 6> kPalette = {
      cv::Scalar(0, 255, 0),   cv::Scalar(255, 160, 0), cv::Scalar(0, 165, 255),
      cv::Scalar(255, 0, 255), cv::Scalar(0, 255, 255), cv::Scalar(255, 255, 255)};
  return kPalette[static_cast<std::size_t>(k) % kPalette.size()];
}

std::string RegionName(int k) {
  // Appended rather than "R" + std::to_string(...), which trips GCC 12's -Wrestrict false positive.
  std::string name = "R";
  name += std::to_string(k + 1);
  return name;
}

nlohmann::json BoxJson(const Box& b) { return {{"x", b.x}, {"y", b.y}, {"w", b.w}, {"h", b.h}}; }

long long CountAbove(const cv::Mat1f& map, double threshold) {
  return map.empty() ? 0 : cv::countNonZero(map > threshold);
}

// A map computed on the R1 crop, scaled to 8 bits (saturating) in a full-frame canvas that is 0
// outside R1.
cv::Mat1b OnFrame(const cv::Mat1f& crop_map, const Box& r1, const cv::Size& frame, double scale) {
  cv::Mat1b out(frame, uchar{0});
  if (crop_map.empty() || crop_map.size() != r1.rect().size()) return out;
  cv::Mat1b window = out(r1.rect());
  crop_map.convertTo(window, CV_8U, scale);  // writes into the canvas: same size and type
  return out;
}

cv::Mat3b Dimmed(const cv::Mat3b& bgr, double brightness) {
  cv::Mat3b out;
  bgr.convertTo(out, -1, brightness);
  return out;
}

// Draws `text` on a dark backing box with its top-left corner at `anchor`, moved right past the
// labels already `placed` (nested regions often share a corner), and kept inside the canvas.
void PutLabel(cv::Mat3b& canvas, const std::string& text, cv::Point anchor,
              const cv::Scalar& colour, const Pen& pen, std::vector<cv::Rect>& placed) {
  int baseline = 0;
  const cv::Size size =
      cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, pen.font_scale, pen.thickness, &baseline);
  const int pad = 2 * pen.thickness;
  cv::Rect backing(anchor.x, anchor.y, size.width + 2 * pad, size.height + baseline + 2 * pad);
  for (bool moved = true; moved;) {
    moved = false;
    for (const cv::Rect& other : placed)
      if ((backing & other).area() > 0) {
        backing.x = other.x + other.width + pad;
        moved = true;
      }
  }
  backing.x = std::clamp(backing.x, 0, std::max(0, canvas.cols - backing.width));
  backing.y = std::clamp(backing.y, 0, std::max(0, canvas.rows - backing.height));
  placed.push_back(backing);
  cv::rectangle(canvas, backing, cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(canvas, text, {backing.x + pad, backing.y + pad + size.height},
              cv::FONT_HERSHEY_SIMPLEX, pen.font_scale, colour, pen.thickness, cv::LINE_AA);
}

cv::Mat3b DrawSuperpixels(const cv::Mat3b& bgr, const OcclusionEdges& oaocc) {
  cv::Mat3b out = Dimmed(bgr, 0.5);
  const cv::Mat1i& labels = oaocc.superpixels.labels;
  if (labels.size() != oaocc.crop.size()) return out;
  cv::Mat3b window = out(oaocc.r1.rect());
  window.setTo(cv::Scalar(0, 255, 255), labels == 0);  // label 0 = boundary
  return out;
}

cv::Mat3b DrawOcclusion(const OcclusionEdges& oaocc, const cv::Size& frame) {
  cv::Mat3b out;
  cv::applyColorMap(OnFrame(oaocc.occlusion, oaocc.r1, frame, 255.0), out, cv::COLORMAP_INFERNO);
  return out;
}

cv::Mat3b DrawRegions(const cv::Mat3b& bgr, const MultilayerRegions& regions) {
  cv::Mat3b out = bgr.clone();
  const Pen pen = PenFor(bgr.size());
  std::vector<cv::Rect> placed;
  for (int k = 0; k < regions.num_layers(); ++k) {
    const Box region = ClipToImage(regions.layers[k], bgr.cols, bgr.rows);
    if (region.empty()) continue;
    cv::rectangle(out, region.rect(), RegionColour(k), pen.thickness);
    PutLabel(out, RegionName(k), {region.x + pen.thickness, region.y + pen.thickness},
             RegionColour(k), pen, placed);
  }
  return out;
}

// Region k's best proposals, the best drawn last (on top); colour from red (best) to yellow
// (the last one shown).
cv::Mat3b DrawProposals(const cv::Mat3b& bgr, const MultilayerRegions& regions, int k,
                        const std::vector<ScoredBox>& boxes, int drawn) {
  cv::Mat3b out = Dimmed(bgr, 0.7);
  const Pen pen = PenFor(bgr.size());
  const Box region = ClipToImage(regions.layers[k], bgr.cols, bgr.rows);
  if (!region.empty()) cv::rectangle(out, region.rect(), RegionColour(k), pen.thickness + 1);
  for (int i = drawn - 1; i >= 0; --i) {
    const double t = drawn > 1 ? static_cast<double>(i) / (drawn - 1) : 0.0;
    cv::rectangle(out, boxes[i].box.rect(), cv::Scalar(0, 255 * t, 255), 1);
  }
  std::vector<cv::Rect> placed;
  PutLabel(out,
           RegionName(k) + ": best " + std::to_string(drawn) + " of " +
               std::to_string(boxes.size()) + " proposals (red = best)",
           {0, 0}, RegionColour(k), pen, placed);
  return out;
}

}  // namespace

Result<StageImages> RenderStageImages(const FrameTrace& trace, const cv::Mat3b& bgr,
                                      const StageImageOptions& options) {
  const MultilayerRegions& regions = trace.geometry.regions;
  const int layers = regions.num_layers();
  if (layers == 0 || ClipToImage(regions.layers.front(), bgr.cols, bgr.rows).empty())
    return Status::InvalidArgument("the bundle's R1 does not cover the frame");
  const OcclusionEdges& oaocc = trace.oaocc;
  const std::vector<RegionProposals>& per_region = trace.regions.per_region;
  if (per_region.size() != static_cast<std::size_t>(layers) ||
      trace.regions.stats.size() != per_region.size())
    return Status::InvalidArgument("the trace has no proposals of every region");

  StageImages out;
  const cv::Size frame = bgr.size();
  out.images.push_back({"base_edges", OnFrame(oaocc.base_edge, oaocc.r1, frame, 255.0)});
  out.images.push_back(
      {"enhanced_edges", OnFrame(oaocc.enhanced, oaocc.r1, frame, 255.0 / layers)});
  out.images.push_back({"superpixels", DrawSuperpixels(bgr, oaocc)});
  out.images.push_back({"occlusion", DrawOcclusion(oaocc, frame)});
  out.images.push_back({"regions", DrawRegions(bgr, regions)});

  nlohmann::json& counts = out.counts;
  counts["width"] = bgr.cols;
  counts["height"] = bgr.rows;
  counts["layers"] = layers;
  counts["edge_threshold"] = options.edge_threshold;
  counts["r1"] = BoxJson(oaocc.r1);
  counts["base_edge_pixels"] = CountAbove(oaocc.base_edge, options.edge_threshold);
  counts["enhanced_edge_pixels"] = CountAbove(oaocc.enhanced, options.edge_threshold);
  counts["superpixels"] = oaocc.superpixels.count;
  counts["occlusion_edge_pixels"] = CountAbove(oaocc.occlusion, options.edge_threshold);
  counts["regions"] = nlohmann::json::array();
  for (int k = 0; k < layers; ++k) {
    const EdgeBoxStats& stats = trace.regions.stats[k];
    const std::vector<ScoredBox>& boxes = per_region[k].boxes;
    const int drawn =
        std::min(std::max(0, options.proposals_drawn), static_cast<int>(boxes.size()));
    out.images.push_back(
        {"proposals_" + RegionName(k), DrawProposals(bgr, regions, k, boxes, drawn)});
    nlohmann::json region = BoxJson(ClipToImage(regions.layers[k], bgr.cols, bgr.rows));
    region["name"] = RegionName(k);
    region["edge_pixels"] = stats.edge_pixels;
    region["edge_groups"] = stats.edge_groups;
    region["windows_scored"] = stats.windows_visited;
    region["windows_nonzero"] = stats.windows_nonzero;
    region["windows_refined"] = stats.windows_refined;
    region["boxes_after_nms"] = stats.boxes_out;
    region["proposals_kept"] = boxes.size();
    region["proposals_drawn"] = drawn;
    counts["regions"].push_back(std::move(region));
  }
  // After the cross-region merge, as the detector regresses them.
  counts["proposals_total"] = trace.regressed.proposals.boxes.size() + trace.regressed.dropped;
  return out;
}

Status WriteStageImages(const StageImages& stages, const std::string& base_path) {
  for (const StageImage& image : stages.images) {
    const Status written =
        WritePngAtomically(base_path + "_stage_" + image.name + ".png", image.pixels);
    if (!written.ok()) return written;
  }
  return WriteFileAtomically(base_path + "_stages.json", stages.counts.dump(2) + "\n");
}

}  // namespace tod
