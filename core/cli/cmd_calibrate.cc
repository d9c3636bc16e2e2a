// tod calibrate --model DIR --data DIR [--split train | --split-file F]
// Measures a bundle's horizon reference (the training camera's horizon as the self-calibration
// estimator sees it) over frames of the camera it was trained on, and writes it into the
// bundle's manifest. `tod train` does this itself; this is for bundles made before it did.
#include <cstdio>
#include <iostream>

#include "core/calibration/horizon_reference.h"
#include "core/cli/commands.h"
#include "core/cli/dataset_options.h"
#include "core/pipeline/model_bundle.h"

namespace tod::cli {

Runner AddCalibrateCommand(CLI::App& app) {
  struct Args {
    DatasetArgs data = DatasetArgsOfSplit("train");
    std::string model;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "measure a bundle's horizon reference on its training camera's frames");
  AddDatasetOptions(cmd, args->data, /*bad_frames=*/false);
  cmd->add_option("--model", args->model, "model bundle directory (its manifest is updated)")
      ->required();
  return [args] {
    auto bundle = LoadModelBundle(args->model);
    if (!bundle.ok()) return Fail(bundle.status().message());
    auto dataset = OpenDataset(DatasetSelectionFrom(args->data).Spec());
    if (!dataset.ok()) return Fail(dataset.status().message());
    const int width = bundle->regions.image_width, height = bundle->regions.image_height;
    std::vector<HorizonEstimate> estimates;
    for (std::size_t i = 0; i < (*dataset)->size(); ++i) {
      auto sample = (*dataset)->Load(i);
      if (!sample.ok()) return Fail(sample.status().message());
      if (sample->image.cols != width || sample->image.rows != height)
        return Fail("frame " + sample->name + " is " + std::to_string(sample->image.cols) + "x" +
                    std::to_string(sample->image.rows) + ", the bundle was trained on " +
                    std::to_string(width) + "x" + std::to_string(height) +
                    " frames: calibrate on the training camera's frames");
      estimates.push_back(EstimateHorizon(sample->image));
    }
    auto reference = ReferenceFromEstimates(estimates, height);
    if (!reference.ok()) return Fail(reference.status().message());
    const Status st = UpdateManifestField(args->model, "horizon_reference", reference->ToJson());
    if (!st.ok()) return Fail(st.message());
    std::printf("horizon reference of %s: row %.1f (spread %.1f) over %d of %zu frames\n",
                args->model.c_str(), reference->row, reference->spread, reference->frames,
                estimates.size());
    return 0;
  };
}

}  // namespace tod::cli
