#include "core/pipeline/pipeline_params.h"

#include <string>

namespace tod {
namespace {

// Reads j[key] into value when present, keeping the default otherwise.
template <typename T>
void Read(const nlohmann::json& j, const char* key, T& value) {
  if (j.contains(key)) value = j.at(key).get<T>();
}

}  // namespace

nlohmann::json ToJson(const PipelineParams& p) {
  nlohmann::json j;
  j["regions"] = {{"num_layers", p.regions.num_layers},
                  {"restarts", p.regions.restarts},
                  {"max_iterations", p.regions.max_iterations},
                  {"margin_fraction", p.regions.margin_fraction},
                  {"seed", p.regions.seed}};
  j["gradient_edges"] = {{"smooth_radius", p.gradient_edges.smooth_radius},
                         {"normalise_percentile", p.gradient_edges.normalise_percentile}};
  j["superpixels"] = {{"k", p.superpixels.k},
                      {"alpha", p.superpixels.alpha},
                      {"beta", p.superpixels.beta},
                      {"iterations", p.superpixels.iterations}};
  const EdgeBoxParams& b = p.boxes;
  j["boxes"] = {{"alpha", b.alpha},
                {"beta", b.beta},
                {"min_score", b.min_score},
                {"max_boxes", b.max_boxes},
                {"edge_min_mag", b.edge_min_mag},
                {"edge_merge_thr", b.edge_merge_thr},
                {"cluster_min_mag", b.cluster_min_mag},
                {"max_aspect_ratio", b.max_aspect_ratio},
                {"min_box_area", b.min_box_area},
                {"gamma", b.gamma},
                {"kappa", b.kappa},
                {"min_stride", b.min_stride},
                {"refine", b.refine}};
  j["multistride"] = p.multistride;
  j["size_filter"] = p.size_filter;
  j["fusion"] = {{"beta1", p.fusion.beta1}, {"keep_ratio", p.fusion.keep_ratio}};
  j["probability_map"] = {{"min_score", p.probability_map.min_score},
                          {"nms_iou", p.probability_map.nms_iou},
                          {"max_boxes", p.probability_map.max_boxes},
                          {"top_fraction", p.probability_map.top_fraction}};
  return j;
}

Result<PipelineParams> PipelineParamsFromJson(const nlohmann::json& j) {
  PipelineParams p;
  try {
    if (j.contains("regions")) {
      const auto& r = j.at("regions");
      Read(r, "num_layers", p.regions.num_layers);
      Read(r, "restarts", p.regions.restarts);
      Read(r, "max_iterations", p.regions.max_iterations);
      Read(r, "margin_fraction", p.regions.margin_fraction);
      Read(r, "seed", p.regions.seed);
    }
    if (j.contains("gradient_edges")) {
      const auto& g = j.at("gradient_edges");
      Read(g, "smooth_radius", p.gradient_edges.smooth_radius);
      Read(g, "normalise_percentile", p.gradient_edges.normalise_percentile);
    }
    if (j.contains("superpixels")) {
      const auto& s = j.at("superpixels");
      Read(s, "k", p.superpixels.k);
      Read(s, "alpha", p.superpixels.alpha);
      Read(s, "beta", p.superpixels.beta);
      Read(s, "iterations", p.superpixels.iterations);
    }
    if (j.contains("boxes")) {
      const auto& b = j.at("boxes");
      Read(b, "alpha", p.boxes.alpha);
      Read(b, "beta", p.boxes.beta);
      Read(b, "min_score", p.boxes.min_score);
      Read(b, "max_boxes", p.boxes.max_boxes);
      Read(b, "edge_min_mag", p.boxes.edge_min_mag);
      Read(b, "edge_merge_thr", p.boxes.edge_merge_thr);
      Read(b, "cluster_min_mag", p.boxes.cluster_min_mag);
      Read(b, "max_aspect_ratio", p.boxes.max_aspect_ratio);
      Read(b, "min_box_area", p.boxes.min_box_area);
      Read(b, "gamma", p.boxes.gamma);
      Read(b, "kappa", p.boxes.kappa);
      Read(b, "min_stride", p.boxes.min_stride);
      Read(b, "refine", p.boxes.refine);
    }
    Read(j, "multistride", p.multistride);
    Read(j, "size_filter", p.size_filter);
    if (j.contains("fusion")) {
      Read(j.at("fusion"), "beta1", p.fusion.beta1);
      Read(j.at("fusion"), "keep_ratio", p.fusion.keep_ratio);
    }
    if (j.contains("probability_map")) {
      const auto& m = j.at("probability_map");
      Read(m, "min_score", p.probability_map.min_score);
      Read(m, "nms_iou", p.probability_map.nms_iou);
      Read(m, "max_boxes", p.probability_map.max_boxes);
      Read(m, "top_fraction", p.probability_map.top_fraction);
    }
  } catch (const nlohmann::json::exception& e) {
    return Status::InvalidArgument(std::string("parameters: ") + e.what());
  }
  if (p.regions.num_layers < 1 || p.superpixels.k < 1 || p.boxes.alpha <= 0 || p.boxes.alpha >= 1 ||
      p.boxes.min_box_area <= 0)
    return Status::InvalidArgument("parameters out of range (num_layers, k, alpha, min_box_area)");
  return p;
}

}  // namespace tod
