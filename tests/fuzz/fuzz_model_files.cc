// Fuzzes the loaders of a model bundle's learned files (model_bundle.cc reads each into an
// istream): RandomForest::Load (ordr.bin, obdr.bin), OcclusionClassifier::Load (occlusion.bin)
// and PixelEdgeClassifier::Load (edges.bin). Every input is offered to all three; each checks its
// magic number first. What loads is then used as the detector would use it (predictions, the
// edge map of a small image) and saved again, which must give a file that loads.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
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
  std::ostringstream out(std::ios::binary);
  Check(model.Save(out).ok());
  std::istringstream in(out.str(), std::ios::binary);
  tod::Result<Model> again = Model::Load(in, "saved again");
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
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  {
    std::istringstream in(bytes, std::ios::binary);
    tod::Result<tod::RandomForest> forest = tod::RandomForest::Load(in, "fuzz");
    if (forest.ok()) {
      UseForest(*forest);
      UseForest(SaveAndLoad(*forest));
    } else {
      Check(!forest.status().message().empty());
    }
  }
  {
    std::istringstream in(bytes, std::ios::binary);
    tod::Result<tod::OcclusionClassifier> occlusion = tod::OcclusionClassifier::Load(in, "fuzz");
    if (occlusion.ok()) (void)SaveAndLoad(*occlusion);
  }
  {
    std::istringstream in(bytes, std::ios::binary);
    tod::Result<tod::PixelEdgeClassifier> edges = tod::PixelEdgeClassifier::Load(in, "fuzz");
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
