// Fuzzes the loaders of a model bundle's learned files, each decoded as model_bundle.cc does
// (DecodeModel of core/base/binary_io.h over the file's bytes): RandomForest::Load (ordr.bin,
// obdr.bin), OcclusionClassifier::Load (occlusion.bin) and PixelEdgeClassifier::Load (edges.bin).
// Every input is offered to all three; each checks its magic number first. What loads is then used
// as the detector would use it (predictions, the edge map of a small image) and saved again, which
// must give a file that loads.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/forest/random_forest.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;

template <typename Model>
Model SaveAndLoad(const Model& model) {
  tod::Result<std::string> bytes = tod::EncodeModel(model);
  Check(bytes.ok());
  tod::Result<Model> again = tod::DecodeModel<Model>(*bytes, "saved again");
  Check(again.ok());
  return std::move(again).value();
}

void UseForest(const tod::RandomForest& forest) {
  if (forest.num_features() > 4096) return;  // a real but wide forest: the rows would be big
  const int cols = std::max(forest.num_features(), 1);
  cv::Mat1f rows(3, cols);
  rows.row(0).setTo(0.f);
  rows.row(1).setTo(-1e30f);
  rows.row(2).setTo(std::numeric_limits<float>::quiet_NaN());
  const std::vector<float> batch = forest.PredictBatch(rows);
  Check(batch.size() == 3);
  for (int r = 0; r < rows.rows; ++r) {
    const float one = forest.Predict(rows[r]);
    Check(one == batch[r] || (one != one && batch[r] != batch[r]));  // bit-identical, NaN too
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  {
    tod::Result<tod::RandomForest> forest = tod::DecodeModel<tod::RandomForest>(bytes, "fuzz");
    if (forest.ok()) {
      UseForest(*forest);
      UseForest(SaveAndLoad(*forest));
    } else {
      Check(!forest.status().message().empty());
    }
  }
  {
    tod::Result<tod::OcclusionClassifier> occlusion =
        tod::DecodeModel<tod::OcclusionClassifier>(bytes, "fuzz");
    if (occlusion.ok()) {
      (void)SaveAndLoad(*occlusion);
    } else {
      Check(!occlusion.status().message().empty());
    }
  }
  {
    tod::Result<tod::PixelEdgeClassifier> edges =
        tod::DecodeModel<tod::PixelEdgeClassifier>(bytes, "fuzz");
    if (edges.ok()) {
      const tod::PixelEdgeClassifier again = SaveAndLoad(*edges);
      // A small textured image (fixed seed: a run must be repeatable). The values are not
      // checked: a file may hold any finite leaf values, only a trained one keeps them in [0, 1].
      cv::Mat3b image(24, 32);
      cv::RNG rng(1);
      rng.fill(image, cv::RNG::UNIFORM, 0, 256);
      for (const tod::PixelEdgeClassifier* classifier : {&std::as_const(*edges), &again}) {
        Check(classifier->Compute(image).size() == image.size());
      }
    }
  }
  return 0;
}
