// The model bundle: a directory with manifest.json (format version, creation time, training data,
// every parameter, the regions, the size filter, its own eval numbers, and size + checksum of each
// learned file) plus the learned models. Written to a temporary directory and renamed, so a crash
// never leaves half a bundle; loading checks everything and names the file and the problem.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "core/base/status.h"
#include "core/calibration/horizon_reference.h"
#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/forest/random_forest.h"
#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/pipeline_params.h"
#include "core/proposals/size_filter.h"

namespace tod {

inline constexpr int kBundleFormatVersion = 1;

struct ModelBundle {
  PipelineParams params;
  MultilayerRegions regions;
  SizeFilter size_filter;
  // The training camera's horizon as EstimateHorizon sees it; none in bundles made before
  // self-calibration (their frames keep the bundle's geometry, and say so).
  std::optional<HorizonReference> horizon_reference;
  EdgeKind edge_kind = EdgeKind::kPixelForest;
  std::shared_ptr<const EdgeSource> edges;
  std::string sed_model_file;  // for kSed: file name inside the bundle
  OcclusionClassifier occlusion;
  RandomForest ordr;
  RandomForest obdr;
  nlohmann::json training;  // what it was trained on (data, frames, seed, timings)
  nlohmann::json eval;      // its own eval numbers (may be null)
  std::string created;      // ISO 8601, set when saved
  std::string version;      // human version label, e.g. "synth-2026-11-22"
};

// Writes `bundle` to `dir` atomically (temporary sibling directory, then rename; an existing
// bundle at `dir` is replaced only once the new one is complete).
// sed_model_source: path of the SED model file to copy in (only for EdgeKind::kSed).
Status SaveModelBundle(const ModelBundle& bundle, const std::string& dir,
                       const std::string& sed_model_source = "");

Result<ModelBundle> LoadModelBundle(const std::string& dir);

// Rewrites one top-level field of manifest.json ("eval" numbers, "horizon_reference"),
// atomically via a temporary file.
Status UpdateManifestField(const std::string& dir, const std::string& field,
                           const nlohmann::json& value);

// Current UTC time as ISO 8601.
std::string NowIso8601();

}  // namespace tod
