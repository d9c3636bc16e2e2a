#include "core/training/training_classifiers.h"

#include <memory>
#include <string>

#include "core/edges/edge_labels.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/training/trainer.h"

namespace tod::training {
namespace {

constexpr char kFewFramesHint[] =
    "out-of-fold maps train each classifier again on each half of the classifier frames; with "
    "few frames, --paper out_of_fold_maps trains without the halves";

// Trains the fold copies of a classifier (nothing when folds are off): fit(frames of fold f,
// name) for each fold f, then install(upstream bundle of fold f, the copy).
template <typename Fit, typename Install>
Status TrainFoldCopies(ClassifierFolds& folds, const std::vector<int>& which,
                       const std::string& name, const Fit& fit, const Install& install) {
  for (int fold = 0; folds.enabled && fold < kFolds; ++fold) {
    auto copy = fit(folds.InFold(which, fold), name + " of fold " + std::to_string(fold));
    if (!copy.ok()) return copy.status().WithContext(kFewFramesHint);
    install(folds.upstream[fold], std::move(*copy));
  }
  return Status::Ok();
}

// An edge source that is not learned has seen no frame: every fold uses it as it is.
void ShareUnlearnedEdges(const ModelBundle& bundle, ClassifierFolds& folds) {
  for (ModelBundle& upstream : folds.upstream) {
    upstream.edge_kind = bundle.edge_kind;
    upstream.edges = bundle.edges;
    upstream.params.prior_correction.edge_odds = bundle.params.prior_correction.edge_odds;
  }
}

}  // namespace

std::vector<int> ClassifierFrames(const TrainingRun& run, const Survey& survey) {
  std::vector<int> out;
  const int count = static_cast<int>(survey.usable.size());
  for (int j : SpreadIndices(count, run.options().classifier_frames))
    out.push_back(survey.usable[j]);
  return out;
}

// §3.4 step 1: the base edge source. Samples are extracted frame by frame.
Status TrainEdgeSource(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                       ClassifierFolds& folds, nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  bundle.edge_kind = options.edge_source;
  switch (options.edge_source) {
    case EdgeKind::kGradient:
      bundle.edges = CreateGradientEdgeSource(options.params.gradient_edges);
      parts["edges"] = {{"kind", EnumString(EdgeKind::kGradient)}, {"learned", false}};
      ShareUnlearnedEdges(bundle, folds);
      return Status::Ok();
    case EdgeKind::kSed: {
      auto sed = CreateSedEdgeSource(options.sed_model);
      if (!sed.ok()) return sed.status().WithContext("loading the SED edge model");
      bundle.edges = std::shared_ptr<const EdgeSource>(std::move(*sed));
      parts["edges"] = {
          {"kind", EnumString(EdgeKind::kSed)}, {"learned", false}, {"model", options.sed_model}};
      ShareUnlearnedEdges(bundle, folds);
      return Status::Ok();
    }
    case EdgeKind::kPixelForest:
      break;  // trained below
  }
  const std::vector<int> which = ClassifierFrames(run, survey);
  PixelEdgeParams edge_params = options.edge_params;
  edge_params.forest.seed = options.seed;
  if (options.threads > 0) edge_params.forest.threads = options.threads;  // --threads bounds all
  run.Say("pixel edge classifier: samples from " + std::to_string(which.size()) + " frames");
  const Box r1 = bundle.regions.layers.front();
  std::vector<EdgeSamples> per_frame(run.num_frames());
  const Status st = run.FirstError(which, run.ForEachFrame(which, [&](int i, const Sample& s) {
    const EdgeTrainingFrame frame{s.image(r1.rect()).clone(), LabelMap(s)(r1.rect()).clone()};
    auto samples = ExtractEdgeSamples(frame, edge_params, static_cast<std::size_t>(i));
    if (!samples.ok()) return samples.status();
    per_frame[i] = std::move(*samples);
    return Status::Ok();
  }));
  if (!st.ok()) return st.WithContext("pixel edge classifier");
  std::size_t samples = 0;
  const auto fit = [&](const std::vector<int>& frames,
                       const std::string& name) -> Result<PixelEdgeClassifier> {
    EdgeSamples all;
    for (int i : frames) AppendEdgeSamples(all, per_frame[i]);
    samples = all.targets.size();
    run.Say("training the " + name + " on " + std::to_string(all.targets.size()) + " samples");
    auto classifier = PixelEdgeClassifier::TrainOnSamples(all, edge_params);
    if (!classifier.ok()) return classifier.status().WithContext("training the " + name);
    return classifier;
  };
  auto classifier = fit(which, "pixel edge classifier");
  if (!classifier.ok()) return classifier.status();
  const auto odds = [&](const PixelEdgeClassifier& c) {
    return options.prior_correction ? c.sampled_odds_scale() : 1.0;
  };
  bundle.params.prior_correction.edge_odds = odds(*classifier);
  parts["edges"] = {{"kind", EnumString(EdgeKind::kPixelForest)},
                    {"learned", true},
                    {"trained", true},
                    {"frames", which.size()},
                    {"samples", samples},
                    {"prior_odds", bundle.params.prior_correction.edge_odds},
                    {"trees", edge_params.forest.num_trees},
                    {"negatives_per_positive", edge_params.negatives_per_positive}};
  bundle.edges = std::make_shared<PixelEdgeClassifier>(std::move(*classifier));
  return TrainFoldCopies(folds, which, "pixel edge classifier", fit,
                         [&](ModelBundle& upstream, PixelEdgeClassifier copy) {
                           upstream.edge_kind = bundle.edge_kind;
                           upstream.params.prior_correction.edge_odds = odds(copy);
                           upstream.edges = std::make_shared<PixelEdgeClassifier>(std::move(copy));
                         });
}

// §3.4 steps 2-5: the occlusion classifier on superpixel boundaries, pairs frame by frame.
Status TrainOcclusionClassifier(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                                ClassifierFolds& folds, nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  const std::vector<int> which = ClassifierFrames(run, survey);
  OcclusionParams params = options.occlusion_params;
  params.forest.seed = options.seed;
  if (options.threads > 0) params.forest.threads = options.threads;
  run.Say("occlusion classifier: pairs from " + std::to_string(which.size()) + " frames");
  std::vector<OcclusionSamples> per_frame(run.num_frames());
  const Status st = run.FirstError(which, run.ForEachFrame(which, [&](int i, const Sample& s) {
    const ModelBundle& upstream = folds.For(bundle, i);
    const Result<OcclusionEdges> computed = ComputeOcclusionEdges(
        s.image, bundle.regions, *upstream.edges, nullptr, upstream.params, /*enhance=*/true);
    if (!computed.ok()) return computed.status();
    const OcclusionEdges& oaocc = *computed;
    const OcclusionTrainingFrame frame{oaocc.crop, oaocc.enhanced, oaocc.superpixels,
                                       LabelMap(s)(oaocc.r1.rect()).clone()};
    auto samples = ExtractOcclusionSamples(frame, params, static_cast<std::size_t>(i));
    if (!samples.ok()) return samples.status();
    per_frame[i] = std::move(*samples);
    return Status::Ok();
  }));
  if (!st.ok()) return st.WithContext("occlusion classifier");
  std::size_t positives = 0;
  const auto fit = [&](const std::vector<int>& frames,
                       const std::string& name) -> Result<OcclusionClassifier> {
    OcclusionSamples all;
    for (int i : frames) AppendOcclusionSamples(all, per_frame[i]);
    positives = all.positive_targets.size();
    run.Say("training the " + name + " on " + std::to_string(positives) + " contour pairs");
    auto classifier = OcclusionClassifier::FitOnSamples(std::move(all), params);
    if (!classifier.ok()) return classifier.status().WithContext("training the " + name);
    return classifier;
  };
  const auto odds = [&](const OcclusionClassifier& c) {
    return options.prior_correction ? c.sampled_odds_scale() : 1.0;
  };
  if (Status st = TrainFoldCopies(folds, which, "occlusion classifier", fit,
                                  [&](ModelBundle& upstream, OcclusionClassifier copy) {
                                    upstream.params.prior_correction.occlusion_odds = odds(copy);
                                    upstream.occlusion = std::move(copy);
                                  });
      !st.ok())
    return st;
  auto classifier = fit(which, "occlusion classifier");
  if (!classifier.ok()) return classifier.status();
  bundle.occlusion = std::move(*classifier);
  bundle.params.prior_correction.occlusion_odds = odds(bundle.occlusion);
  parts["occlusion"] = {{"learned", true},
                        {"trained", true},
                        {"frames", which.size()},
                        {"contour_pairs", positives},
                        {"edge_maps", folds.enabled ? "out_of_fold" : "in_sample"},
                        {"fold_layout", kFoldLayoutName},
                        {"prior_odds", bundle.params.prior_correction.occlusion_odds},
                        {"trees", params.forest.num_trees},
                        {"negatives_per_positive", params.negatives_per_positive}};
  return Status::Ok();
}

}  // namespace tod::training
