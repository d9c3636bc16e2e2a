// Fuzzes the manifest.json half of LoadModelBundle: JSON parsing, then PipelineParamsFromJson,
// MultilayerRegions::FromJson and SizeFilter::FromJson on the "params", "regions" and
// "size_filter" members, with the same exception handling as model_bundle.cc. What is accepted is
// used the way the detector starts using it (regions clipped to the frame, boxes through the
// size filter) and written back to JSON (regions must read back the same).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string_view>

#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/pipeline_params.h"
#include "core/proposals/size_filter.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;

void UseRegions(const tod::MultilayerRegions& regions) {
  Check(regions.image_width > 0 && regions.image_height > 0 && !regions.layers.empty());
  for (const tod::Box& layer : regions.layers) {
    Check(!layer.empty());
    Check(tod::ClipToImage(layer, regions.image_width, regions.image_height) == layer);
    Check(layer.area() <= static_cast<long long>(regions.image_width) * regions.image_height);
  }
  const tod::Result<tod::MultilayerRegions> again =
      tod::MultilayerRegions::FromJson(regions.ToJson());
  Check(again.ok() && again->layers == regions.layers);
}

void UseSizeFilter(const tod::SizeFilter& filter) {
  for (const tod::Box& box :
       {tod::Box{0, 0, 1, 1}, tod::Box{100, 400, 30, 20}, tod::Box{2000, 1000, 48, 30}}) {
    (void)filter.Keep(box);
  }
  (void)filter.Apply({{tod::Box{10, 10, 5, 5}, 1.f}});
  (void)tod::SizeFilter::FromJson(filter.ToJson());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const nlohmann::json::exception&) {
    return 0;  // model_bundle.cc: DataLoss "not valid JSON"
  }
  // Each part on its own (not stopping at the first bad one), so one broken member does not hide
  // the others from the fuzzer.
  try {
    const tod::Result<tod::PipelineParams> params =
        tod::PipelineParamsFromJson(manifest.at("params"));
    // Written back as tod train does (not read again: JSON has no infinity, so 1e999 would
    // come back as null).
    if (params.ok()) (void)tod::ToJson(*params).dump();
  } catch (const nlohmann::json::exception&) {
  }
  try {
    const tod::Result<tod::MultilayerRegions> regions =
        tod::MultilayerRegions::FromJson(manifest.at("regions"));
    if (regions.ok()) UseRegions(*regions);
  } catch (const nlohmann::json::exception&) {
  }
  try {
    UseSizeFilter(tod::SizeFilter::FromJson(manifest.at("size_filter")));
  } catch (const nlohmann::json::exception&) {
  }
  return 0;
}
