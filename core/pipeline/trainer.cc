#include "core/pipeline/trainer.h"

#include <array>
#include <atomic>
#include <chrono>
#include <limits>
#include <mutex>
#include <optional>

#include "core/base/memory_usage.h"
#include "core/edges/edge_labels.h"
#include "core/pipeline/dataset_factory.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/map_isolation_fit.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"
#include "core/pipeline/probability_map.h"
#include "core/pipeline/training_folds.h"
#include "core/proposals/ground_plane_size_prior.h"

namespace tod {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One training run: the split, progress lines (each with the peak RSS so far), step timings.
// Frames are streamed: every step loads the frames it visits and keeps only what the next step
// needs (samples, statistics), so memory does not grow with the number of frames.
class TrainingRun {
 public:
  explicit TrainingRun(const TrainOptions& options) : options_(options) {}

  Status Open() {
    std::vector<DatasetSpec> specs = {{options_.data_root, options_.split, options_.format,
                                       options_.split_file, options_.max_frames}};
    for (const std::string& root : options_.more_data)
      specs.push_back({root, options_.split, "auto", "", options_.max_frames});
    auto selection = SelectFrames(specs);
    if (!selection.ok()) return selection.status();
    selection_ = std::move(*selection);
    frames_ = selection_.frames;
    return Status::Ok();
  }

  void Say(const std::string& line) {
    if (!options_.progress) return;
    std::lock_guard lock(say_mutex_);
    char rss[48];
    std::snprintf(rss, sizeof rss, " [peak RSS %.0f MB]", PeakRssMb());
    options_.progress(line + rss);
  }
  void StartStep() { step_started_ = Clock::now(); }
  void EndStep(const std::string& name) { seconds_[name] = SecondsSince(step_started_); }

  // Runs body(frame index, sample) over `which` (positions into frames()), loading each frame
  // when it is visited. A frame that fails is that frame's error.
  std::vector<Status> ForEachFrame(const std::vector<int>& which,
                                   const std::function<Status(int, const Sample&)>& body) {
    return ParallelFor(static_cast<int>(which.size()), options_.threads, [&](int j) -> Status {
      auto sample = selection_.dataset->Load(frames_[which[j]]);
      if (!sample.ok()) return sample.status();
      return body(which[j], *sample);
    });
  }
  // The error of the first frame that failed, named.
  Status FirstError(const std::vector<int>& which, const std::vector<Status>& statuses) const {
    for (std::size_t j = 0; j < statuses.size(); ++j)
      if (!statuses[j].ok()) return statuses[j].WithContext("frame " + FrameName(which[j]));
    return Status::Ok();
  }
  std::string FrameName(int position) const { return selection_.dataset->name(frames_[position]); }
  // Which of the datasets (data_root, then more_data) each frame position comes from.
  const std::vector<int>& FrameSources() const { return selection_.source; }

  const TrainOptions& options() const { return options_; }
  const std::string& format() const { return selection_.format; }
  int num_frames() const { return static_cast<int>(frames_.size()); }
  const nlohmann::json& seconds() const { return seconds_; }
  Clock::time_point started() const { return started_; }

 private:
  const TrainOptions& options_;
  FrameSelection selection_;
  std::vector<int> frames_;
  std::mutex say_mutex_;
  Clock::time_point started_ = Clock::now();
  Clock::time_point step_started_ = Clock::now();
  nlohmann::json seconds_ = nlohmann::json::object();
};

// What the first pass over the split learns: the frame size, the obstacles, the usable frames.
struct Survey {
  int width = 0, height = 0;
  std::vector<ObstacleFootprint> footprints;
  std::vector<Box> obstacle_boxes;
  std::vector<int> usable;  // positions of the frames every later step visits
  std::vector<SkippedFrame> skipped;
  std::vector<ObstacleCutout> cutouts;  // of the usable frames, with TrainOptions::pasted_copies
};

Result<Survey> SurveyFrames(TrainingRun& run) {
  const int n = run.num_frames();
  run.Say("surveying " + std::to_string(n) + " training frames from " + run.options().data_root);
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  std::vector<cv::Size> sizes(n);
  std::vector<std::vector<ObstacleFootprint>> per_frame(n);
  std::vector<std::vector<ObstacleCutout>> cutouts(n);
  const bool cut_out = run.options().pasted_copies > 0;
  const std::vector<Status> statuses = run.ForEachFrame(all, [&](int i, const Sample& s) {
    sizes[i] = s.image.size();
    for (const ObstacleInstance& inst : s.instances) {
      per_frame[i].push_back({inst.box, inst.pixel_count()});
      if (!cut_out) continue;
      ObstacleCutout cutout = CutOutObstacle(s, inst, i, run.options().paste);
      if (!cutout.patch.empty()) cutouts[i].push_back(std::move(cutout));
    }
    return Status::Ok();
  });
  Survey survey;
  const Status bad = ApplyBadFramePolicy(
      statuses, [&](int i) { return run.FrameName(i); }, run.options().on_bad_frame,
      &survey.skipped);
  if (!bad.ok()) return bad;
  for (const SkippedFrame& f : survey.skipped)
    run.Say("skipped frame " + f.frame + ": " + f.reason);
  for (int i = 0; i < n; ++i) {
    if (!statuses[i].ok()) continue;
    if (survey.usable.empty()) survey.width = sizes[i].width, survey.height = sizes[i].height;
    if (sizes[i] != cv::Size(survey.width, survey.height)) {
      return Status::InvalidArgument(
          "frame " + run.FrameName(i) + " is " + std::to_string(sizes[i].width) + "x" +
          std::to_string(sizes[i].height) + ", the split's first frame " +
          std::to_string(survey.width) + "x" + std::to_string(survey.height) +
          ": train on frames of one camera (a bundle then maps onto any frame size)");
    }
    survey.usable.push_back(i);
    for (const ObstacleFootprint& f : per_frame[i]) {
      survey.footprints.push_back(f);
      survey.obstacle_boxes.push_back(f.box);
    }
    for (ObstacleCutout& c : cutouts[i]) survey.cutouts.push_back(std::move(c));
  }
  if (survey.usable.empty()) return Status::InvalidArgument("no usable training frame");
  run.Say(std::to_string(survey.footprints.size()) + " training obstacles in " +
          std::to_string(survey.usable.size()) + " frames");
  if (cut_out)
    run.Say(std::to_string(survey.cutouts.size()) +
            " of them cut out to paste (the others have void or another obstacle in their ring)");
  return survey;
}

// The ground-plane size prior of the training obstacles, fitted on first use: the size filter
// and both kinds of ground-plane features place the same horizon.
class GroundPlaneFit {
 public:
  explicit GroundPlaneFit(const std::vector<Box>& obstacle_boxes) : boxes_(obstacle_boxes) {}
  const Result<GroundPlaneSizePrior>& Get() {
    if (!fitted_) fitted_.emplace(FitGroundPlaneSizePrior(boxes_));
    return *fitted_;
  }

 private:
  const std::vector<Box>& boxes_;
  std::optional<Result<GroundPlaneSizePrior>> fitted_;
};

// The size filter of `--regions auto` bundles: the ground-plane prior (ours, README "Real
// frames") or the authors' per-band extremes (§4.3). Recorded in parts["size_filter"].
Status DeriveSizeFilter(TrainingRun& run, const Survey& survey, GroundPlaneFit& ground_plane,
                        ModelBundle& bundle, nlohmann::json& parts) {
  const std::string& recipe = run.options().size_filter_recipe;
  if (recipe == "bands") {
    bundle.size_filter = SizeFilter::Derive(survey.obstacle_boxes);
    parts["size_filter"] = {{"recipe", "bands"}, {"obstacles", survey.obstacle_boxes.size()}};
    return Status::Ok();
  }
  if (recipe != "ground_plane")
    return Status::InvalidArgument("--size-filter-recipe must be ground_plane or bands, got '" +
                                   recipe + "'");
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext(
        "fitting the size filter's ground-plane prior (too few "
        "obstacles? --size-filter-recipe bands needs none)");
  bundle.size_filter = GroundPlaneSizeFilter(*prior, survey.obstacle_boxes);
  parts["size_filter"] = {{"recipe", "ground_plane"},
                          {"obstacles", prior->obstacles},
                          {"horizon_y", prior->horizon_y},
                          {"h_per_row", {prior->h_ratio_min, prior->h_ratio_max}},
                          {"w_per_row", {prior->w_ratio_min, prior->w_ratio_max}},
                          {"area_per_row2", {prior->area_ratio_min, prior->area_ratio_max}}};
  char line[128];
  std::snprintf(line, sizeof line, "size filter: horizon at row %.1f, h/d %.3f-%.3f, w/d %.3f-%.3f",
                prior->horizon_y, prior->h_ratio_min, prior->h_ratio_max, prior->w_ratio_min,
                prior->w_ratio_max);
  run.Say(line);
  return Status::Ok();
}

// With ground-plane sizes (PipelineParams::box_features, occlusion_features), their horizon: the
// one the ground-plane size prior fits to the training obstacles, whatever the size filter's
// recipe. `choice` is the option's value, `flag` its name, `part` the manifest key.
Status PlaceGroundPlaneHorizon(TrainingRun& run, GroundPlaneFit& ground_plane,
                               const std::string& choice, const std::string& flag,
                               const std::string& part, GroundPlaneFeatureParams& params,
                               nlohmann::json& parts) {
  if (choice != "ground_plane" && choice != "paper")
    return Status::InvalidArgument(flag + " must be ground_plane or paper, got '" + choice + "'");
  params.ground_plane_size = choice == "ground_plane";
  if (!params.ground_plane_size) {
    parts[part] = {{"size", "paper"}};
    return Status::Ok();
  }
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext("placing the horizon of the ground-plane " + part +
                                      " (too few obstacles? " + flag + " paper needs none)");
  params.horizon_y = prior->horizon_y;
  parts[part] = {{"size", "ground_plane"}, {"horizon_y", params.horizon_y}};
  char line[64];
  std::snprintf(line, sizeof line, ": sizes over the rows below row %.1f", params.horizon_y);
  run.Say(part + line);
  return Status::Ok();
}

Status PlaceFeatureHorizons(TrainingRun& run, GroundPlaneFit& ground_plane, ModelBundle& bundle,
                            nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  if (Status st = PlaceGroundPlaneHorizon(run, ground_plane, options.box_size_features,
                                          "--box-size-features", "box_features",
                                          bundle.params.box_features, parts);
      !st.ok())
    return st;
  return PlaceGroundPlaneHorizon(run, ground_plane, options.occlusion_size_features,
                                 "--occlusion-size-features", "occlusion_features",
                                 bundle.params.occlusion_features, parts);
}

// Multilayer regions and the size filter from the training obstacles (§1.4, §4.3).
Status DeriveGeometry(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                      nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  GroundPlaneFit ground_plane(survey.obstacle_boxes);
  if (options.regions == "laf2020") {
    bundle.regions = Laf2020Regions().ScaledTo(survey.width, survey.height);
    bundle.size_filter = SizeFilter::Laf2020();
    parts["size_filter"] = {{"recipe", "laf2020"}};
    if (survey.width != 2048 || survey.height != 1024) {
      if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok())
        return st;
    }
  } else if (options.regions == "auto") {
    RegionParams region_params = options.params.regions;
    region_params.seed = options.seed;
    auto regions =
        DeriveMultilayerRegions(survey.footprints, survey.width, survey.height, region_params);
    if (!regions.ok()) return regions.status().WithContext("deriving the multilayer regions");
    bundle.regions = *regions;
    if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok()) return st;
  } else {
    return Status::InvalidArgument("--regions must be auto or laf2020, got '" + options.regions +
                                   "'");
  }
  bundle.size_filter.enabled = options.params.size_filter;
  if (Status st = PlaceFeatureHorizons(run, ground_plane, bundle, parts); !st.ok()) return st;
  for (int k = 0; k < bundle.regions.num_layers(); ++k) {
    const Box& r = bundle.regions.layers[k];
    char line[96];  // snprintf: GCC 12 warns (-Wrestrict, falsely) on "R" + std::to_string
    std::snprintf(line, sizeof line, "R%d = [%d, %d, %d x %d]", k + 1, r.x, r.y, r.w, r.h);
    run.Say(line);
  }
  return Status::Ok();
}

// Positions of the frames the edge and occlusion classifiers learn from.
std::vector<int> ClassifierFrames(const TrainingRun& run, const Survey& survey) {
  std::vector<int> out;
  const int count = static_cast<int>(survey.usable.size());
  for (int j : SpreadIndices(count, run.options().classifier_frames))
    out.push_back(survey.usable[j]);
  return out;
}

// Out-of-fold maps (TrainOptions::out_of_fold_maps). The edge and occlusion classifiers fit the
// frames they were trained on far better than a frame they have never seen, so maps computed on
// training frames with them are cleaner than any test frame's, and whatever learns from those
// maps (the occlusion classifier from edge maps, the regressors from occlusion maps and edge
// features) learns from the wrong distribution. Stacked training: each learned part also gets a
// copy trained on each of two folds of frames, and a frame's maps for the next part come from the
// copy trained on the other fold, as they would on a frame never seen. The folds are runs of
// whole drives by default (TrainOptions::fold_layout, training_folds.h).
constexpr int kFolds = 2;

constexpr char kFewFramesHint[] =
    "out-of-fold maps train each classifier again on each half of the classifier frames; with "
    "few frames, --in-sample-maps trains without the halves";

struct ClassifierFolds {
  bool enabled = false;
  std::vector<int> fold_of;  // fold of every frame position (AssignFolds)
  // upstream[f]: the bundle's parameters with the classifiers trained on fold f's frames.
  std::array<ModelBundle, kFolds> upstream;

  ClassifierFolds(bool on, int num_frames, const std::vector<int>& usable,
                  const std::vector<int>& classifier_frames, FoldLayout layout,
                  const std::vector<int>& source)
      : enabled(on),
        fold_of(AssignFolds(num_frames, usable, classifier_frames, kFolds, layout, source)) {}
  int FoldOf(int frame) const { return fold_of[frame]; }
  // The bundle whose classifiers compute frame `i`'s maps for a downstream part.
  const ModelBundle& For(const ModelBundle& bundle, int frame) const {
    return enabled ? upstream[(FoldOf(frame) + 1) % kFolds] : bundle;
  }
  // The positions in `which` that lie in `fold`.
  std::vector<int> InFold(const std::vector<int>& which, int fold) const {
    std::vector<int> out;
    for (int i : which)
      if (FoldOf(i) == fold) out.push_back(i);
    return out;
  }
};

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

// §3.4 step 1: the base edge source. Samples are extracted frame by frame.
Status TrainEdgeSource(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                       ClassifierFolds& folds, nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  bundle.edge_kind = options.edge_source;
  if (options.edge_source == "gradient") {
    bundle.edges = CreateGradientEdgeSource(options.params.gradient_edges);
    parts["edges"] = {{"kind", "gradient"}, {"learned", false}};
    ShareUnlearnedEdges(bundle, folds);
    return Status::Ok();
  }
  if (options.edge_source == "sed") {
    auto sed = CreateSedEdgeSource(options.sed_model);
    if (!sed.ok()) return sed.status().WithContext("loading the SED edge model");
    bundle.edges = std::shared_ptr<const EdgeSource>(std::move(*sed));
    parts["edges"] = {{"kind", "sed"}, {"learned", false}, {"model", options.sed_model}};
    ShareUnlearnedEdges(bundle, folds);
    return Status::Ok();
  }
  if (options.edge_source != "pixel_forest")
    return Status::InvalidArgument("unknown edge source '" + options.edge_source +
                                   "' (pixel_forest, gradient, sed)");
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
  parts["edges"] = {{"kind", "pixel_forest"},
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
        s.image, bundle.regions, *upstream.edges, nullptr, {}, upstream.params, /*enhance=*/true);
    if (!computed.ok()) return computed.status();
    const OcclusionEdges& oaocc = *computed;
    const OcclusionTrainingFrame frame{
        oaocc.crop, oaocc.enhanced, oaocc.superpixels, LabelMap(s)(oaocc.r1.rect()).clone(),
        OcclusionFeaturesOnCrop(OcclusionFeatureOptionsForFrame(bundle, s.image.cols, s.image.rows),
                                oaocc)};
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
                        {"fold_layout", FoldLayoutName(options.fold_layout)},
                        {"prior_odds", bundle.params.prior_correction.occlusion_odds},
                        {"trees", params.forest.num_trees},
                        {"negatives_per_positive", params.negatives_per_positive}};
  return Status::Ok();
}

// Rows of ProposalSet `all` selected by `indices`, as a proposal subset for feature extraction.
ProposalSet Subset(const ProposalSet& all, const std::vector<int>& indices) {
  ProposalSet out;
  out.layer_scale = all.layer_scale;
  for (int i : indices) {
    out.boxes.push_back(all.boxes[i]);
    out.layer.push_back(all.layer[i]);
  }
  return out;
}

// ORDR and OBDR samples of every frame (§6), kept per frame for the calibration folds.
struct RegressorSamples {
  std::vector<cv::Mat1f> ordr_rows, obdr_rows;
  std::vector<std::vector<float>> ordr_targets, obdr_targets;
  // Per row: SelectedSamples::kEveryBag or the negative bag that drew it.
  std::vector<std::vector<int>> ordr_bags, obdr_bags;
  int num_bags = 1;
  long long proposals = 0;
};

// The regressors' rows of one frame, real or with pasted obstacles.
struct FrameRows {
  cv::Mat1f ordr, obdr;
  std::vector<float> ordr_targets, obdr_targets;
  std::vector<int> ordr_bags, obdr_bags;
  long long proposals = 0;

  // Appends the rows of `more` (a pasted copy: its proposals are not counted).
  void Append(const FrameRows& more) {
    ordr.push_back(more.ordr);
    obdr.push_back(more.obdr);
    ordr_targets.insert(ordr_targets.end(), more.ordr_targets.begin(), more.ordr_targets.end());
    obdr_targets.insert(obdr_targets.end(), more.obdr_targets.begin(), more.obdr_targets.end());
    ordr_bags.insert(ordr_bags.end(), more.ordr_bags.begin(), more.ordr_bags.end());
    obdr_bags.insert(obdr_bags.end(), more.obdr_bags.begin(), more.obdr_bags.end());
  }
};

// §6 on one frame: its proposals (maps by `upstream`'s classifiers), ranked by objectness or, with
// `miner`, by the miner's fused score; the selected samples' features and targets. With
// `positives_only` (a pasted copy: its negatives would be the frame's road again) the negatives
// are dropped before any feature is computed.
Result<FrameRows> RegressorRowsOfFrame(const Sample& s, const ModelBundle& bundle,
                                       const ModelBundle& upstream, const ModelBundle* miner,
                                       const SampleSelectionParams& selection, std::uint64_t seed,
                                       bool positives_only) {
  const Result<OcclusionEdges> computed = ComputeOcclusionEdges(
      s.image, bundle.regions, *upstream.edges, &upstream.occlusion,
      OcclusionFeatureOptionsForFrame(bundle, s.image.cols, s.image.rows), upstream.params, true);
  if (!computed.ok()) return computed.status();
  const OcclusionEdges& oaocc = *computed;
  const ProposalSet all = ProposeBoxes(
      oaocc, bundle.regions, bundle.params.boxes,
      DetectorProposalOptions(bundle.params, bundle.regions.num_layers()), bundle.size_filter);
  std::vector<ScoredBox> ranked = all.boxes;  // scored by objectness
  if (miner != nullptr) {
    const RegressedProposals scored = RegressProposals(*miner, s.image, oaocc, bundle.regions, all);
    const std::vector<float> fused = FuseScores(scored.ordr, scored.obdr, bundle.params.fusion);
    for (std::size_t j = 0; j < ranked.size(); ++j) ranked[j].score = fused[j];
  }
  auto selected = SelectTrainingSamples(ranked, s, bundle.regions.RangeLimits(), selection, seed);
  if (!selected.ok()) return selected.status();
  if (positives_only) {
    // Positives come first in both lists, shared (SelectedSamples).
    const std::size_t p = selected->positive_indices.size();
    for (std::vector<int>* v : {&selected->ordr_indices, &selected->obdr_indices,
                                &selected->ordr_bags, &selected->obdr_bags})
      v->resize(p);
    selected->ordr_targets.resize(p);
    selected->obdr_targets.resize(p);
  }
  const BoxFeatureOptions features = FeatureOptionsForFrame(bundle, s.image.cols, s.image.rows);
  FrameRows rows;
  rows.ordr = ComputeProposalFeatures(s.image, oaocc, bundle.regions,
                                      Subset(all, selected->ordr_indices), features);
  rows.obdr = ComputeProposalFeatures(s.image, oaocc, bundle.regions,
                                      Subset(all, selected->obdr_indices), features);
  rows.ordr_targets = std::move(selected->ordr_targets);
  rows.obdr_targets = std::move(selected->obdr_targets);
  rows.ordr_bags = std::move(selected->ordr_bags);
  rows.obdr_bags = std::move(selected->obdr_bags);
  rows.proposals = static_cast<long long>(all.boxes.size());
  return rows;
}

// The cut-outs frame `i` may be pasted with: those of the other frames of its fold, so that no
// part trained on the other fold (out-of-fold maps, the calibration's regressors) sees them.
std::vector<const ObstacleCutout*> DonorsFor(int i, const Survey& survey,
                                             const ClassifierFolds& folds) {
  std::vector<const ObstacleCutout*> donors;
  for (const ObstacleCutout& c : survey.cutouts)
    if (c.frame != i && folds.FoldOf(c.frame) == folds.FoldOf(i)) donors.push_back(&c);
  return donors;
}

// With `miner` (a bundle with trained regressors), the negatives' "hard" share is drawn from the
// proposals the miner's fused score puts above selection.hard_objectness instead of by
// objectness (TrainOptions::mine_hard_negatives). With TrainOptions::pasted_copies, each frame's
// rows are followed by those of its copies with pasted obstacles.
Result<RegressorSamples> CollectRegressorSamples(TrainingRun& run, const Survey& survey,
                                                 const ModelBundle& bundle,
                                                 const ClassifierFolds& folds,
                                                 const ModelBundle* miner = nullptr) {
  const TrainOptions& options = run.options();
  const int n = run.num_frames();
  RegressorSamples out;
  out.ordr_rows.resize(n), out.obdr_rows.resize(n);
  out.ordr_targets.resize(n), out.obdr_targets.resize(n);
  out.ordr_bags.resize(n), out.obdr_bags.resize(n);
  out.num_bags = options.selection.negative_bags;
  std::vector<long long> proposals(n, 0);
  std::atomic<int> done{0};
  const Status st =
      run.FirstError(survey.usable, run.ForEachFrame(survey.usable, [&](int i, const Sample& s) {
        if (cv::countNonZero(s.road) > 0) {
          const ModelBundle& upstream = folds.For(bundle, i);
          const std::uint64_t seed = options.seed * 1000003ULL + static_cast<unsigned>(i);
          auto rows = RegressorRowsOfFrame(s, bundle, upstream, miner, options.selection, seed,
                                           /*positives_only=*/false);
          if (!rows.ok()) return rows.status();
          const std::vector<const ObstacleCutout*> donors =
              options.pasted_copies > 0 ? DonorsFor(i, survey, folds)
                                        : std::vector<const ObstacleCutout*>{};
          for (int copy = 1; copy <= options.pasted_copies && !donors.empty(); ++copy) {
            const std::uint64_t copy_seed = seed + 0x9E3779B97F4A7C15ULL * copy;
            Sample pasted = PasteObstacles(s, donors, copy_seed, options.paste);
            if (pasted.instances.size() == s.instances.size()) continue;  // no place was free
            VoidOwnObstacles(pasted, s.instances.size());
            auto more = RegressorRowsOfFrame(pasted, bundle, upstream, miner, options.selection,
                                             copy_seed, /*positives_only=*/true);
            if (!more.ok()) return more.status().WithContext("pasted copy " + std::to_string(copy));
            rows->Append(*more);
          }
          proposals[i] = rows->proposals;
          out.ordr_rows[i] = std::move(rows->ordr);
          out.obdr_rows[i] = std::move(rows->obdr);
          out.ordr_targets[i] = std::move(rows->ordr_targets);
          out.obdr_targets[i] = std::move(rows->obdr_targets);
          out.ordr_bags[i] = std::move(rows->ordr_bags);
          out.obdr_bags[i] = std::move(rows->obdr_bags);
        }
        const int finished = ++done;
        if (finished % 10 == 0 || finished == static_cast<int>(survey.usable.size()))
          run.Say("proposals and samples: " + std::to_string(finished) + "/" +
                  std::to_string(survey.usable.size()) + " frames");
        return Status::Ok();
      }));
  if (!st.ok()) return st.WithContext("collecting regressor samples");
  for (long long c : proposals) out.proposals += c;
  return out;
}

// The regressors trained on the samples of the frames `in_fold(i)` accepts.
struct Regressors {
  RandomForest ordr, obdr;
  int ordr_samples = 0, obdr_samples = 0;
};
// One regressor on the samples of the frames `in_fold(i)` accepts: with one bag the paper's
// forest; with several (SampleSelectionParams::negative_bags) one forest per bag, on every
// positive and that bag's negatives, with its share of the trees, joined into one forest.
Result<RandomForest> FitBaggedRegressor(const std::vector<cv::Mat1f>& parts,
                                        const std::vector<std::vector<float>>& targets,
                                        const std::vector<std::vector<int>>& bags, int num_bags,
                                        const std::function<bool(int)>& in_fold,
                                        const ForestParams& forest, int& samples) {
  constexpr int kMinSamples = 10;
  std::vector<RandomForest> forests;
  samples = 0;
  for (int bag = 0; bag < num_bags; ++bag) {
    cv::Mat1f x;
    std::vector<float> y;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (parts[i].empty() || !in_fold(static_cast<int>(i))) continue;
      for (int r = 0; r < parts[i].rows; ++r) {
        const int of = bags[i].empty() ? SelectedSamples::kEveryBag : bags[i][r];
        if (of != SelectedSamples::kEveryBag && of != bag) continue;
        x.push_back(parts[i].row(r));
        y.push_back(targets[i][r]);
        if (of == bag || bag == 0) ++samples;
      }
    }
    if (x.rows < kMinSamples)
      return Status::InvalidArgument(
          "too few training samples (" + std::to_string(x.rows) + " in bag " + std::to_string(bag) +
          ", need " + std::to_string(kMinSamples) + "); need frames with obstacles and free space");
    ForestParams params = forest;
    params.num_trees = forest.num_trees / num_bags + (bag < forest.num_trees % num_bags ? 1 : 0);
    params.seed = forest.seed + 7919ULL * static_cast<std::uint64_t>(bag);
    auto fitted = RandomForest::Fit(x, y, params);
    if (!fitted.ok()) return fitted.status();
    forests.push_back(std::move(*fitted));
  }
  if (num_bags == 1) return std::move(forests.front());
  return RandomForest::Join(forests);
}

Result<Regressors> TrainRegressorPair(const RegressorSamples& samples,
                                      const std::function<bool(int)>& in_fold,
                                      ForestParams forest) {
  Regressors out;
  auto ordr = FitBaggedRegressor(samples.ordr_rows, samples.ordr_targets, samples.ordr_bags,
                                 samples.num_bags, in_fold, forest, out.ordr_samples);
  if (!ordr.ok()) return ordr.status().WithContext("ORDR");
  forest.seed += 1;
  auto obdr = FitBaggedRegressor(samples.obdr_rows, samples.obdr_targets, samples.obdr_bags,
                                 samples.num_bags, in_fold, forest, out.obdr_samples);
  if (!obdr.ok()) return obdr.status().WithContext("OBDR");
  out.ordr = std::move(*ordr);
  out.obdr = std::move(*obdr);
  return out;
}

ForestParams RegressorForest(const TrainOptions& options) {
  ForestParams forest = options.regressor;
  forest.seed = options.seed;
  forest.threads = options.threads;
  return forest;
}

// The regressors and the samples they were trained on (kept for the calibration folds).
struct TrainedRegressors {
  RegressorSamples samples;
  Regressors regressors;
};

// Samples, then ORDR and OBDR (§6); with TrainOptions::mine_hard_negatives a second round
// (bootstrapping): the first round's regressors score every training proposal, the negatives
// are drawn again with their hard share by that score, and the regressors train again.
Result<TrainedRegressors> TrainRegressors(TrainingRun& run, const Survey& survey,
                                          const ModelBundle& bundle, const ClassifierFolds& folds) {
  const TrainOptions& options = run.options();
  run.StartStep();
  auto samples = CollectRegressorSamples(run, survey, bundle, folds);
  if (!samples.ok()) return samples.status();
  run.EndStep("proposals_and_samples");

  run.StartStep();
  run.Say("training ORDR and OBDR");
  auto regressors = TrainRegressorPair(
      *samples, [](int) { return true; }, RegressorForest(options));
  if (!regressors.ok()) return regressors.status().WithContext("training the regressors");
  run.EndStep("regressors");
  if (!options.mine_hard_negatives)
    return TrainedRegressors{std::move(*samples), std::move(*regressors)};

  run.StartStep();
  run.Say("mining hard negatives with the first-round regressors");
  ModelBundle miner = bundle;
  miner.ordr = std::move(regressors->ordr);
  miner.obdr = std::move(regressors->obdr);
  auto mined = CollectRegressorSamples(run, survey, bundle, folds, &miner);
  if (!mined.ok()) return mined.status().WithContext("mining hard negatives");
  run.Say("training ORDR and OBDR on the mined samples");
  auto second = TrainRegressorPair(
      *mined, [](int) { return true; }, RegressorForest(options));
  if (!second.ok()) return second.status().WithContext("training the regressors (second round)");
  run.EndStep("hard_negatives");
  return TrainedRegressors{std::move(*mined), std::move(*second)};
}

// Calibration of the obstacles' scores (obstacle_calibration.h) and the map's isolation exponent
// (map_isolation_fit.h), from one out-of-fold pass. The regressors fit their own training frames
// closely, so scores on those frames would be overconfident: each frame is scored by regressors
// trained on the other fold of frames (2-fold cross-fitting). The exponent whose map ranks those
// frames' obstacle pixels best is chosen, then Platt scaling of "covers an obstacle pixel" is
// fitted on the evidence of every component that map yields.
Status CalibrateObstacleScores(TrainingRun& run, const Survey& survey,
                               const RegressorSamples& samples, const ClassifierFolds& folds,
                               ModelBundle& bundle, nlohmann::json& parts) {
  const auto fold_of = [&folds](int frame) { return folds.FoldOf(frame); };
  MapIsolationFit isolation(
      run.options().fit_map_isolation ? DefaultIsolationExponents() : std::vector<float>{0.f},
      bundle.params, run.num_frames());
  for (int fold = 0; fold < kFolds; ++fold) {
    std::vector<int> which;
    for (int i : survey.usable)
      if (fold_of(i) == fold) which.push_back(i);
    if (which.empty()) continue;
    auto pair = TrainRegressorPair(
        samples, [&](int i) { return fold_of(i) != fold; }, RegressorForest(run.options()));
    if (!pair.ok()) return pair.status().WithContext("calibration fold " + std::to_string(fold));
    // Frames of this fold are scored by parts trained on the other fold only: the regressors and,
    // with out-of-fold maps, the classifiers too.
    ModelBundle fold_bundle = folds.For(bundle, which.front());
    fold_bundle.ordr = std::move(pair->ordr);
    fold_bundle.obdr = std::move(pair->obdr);
    const ObstacleDetector detector(std::move(fold_bundle), "calibration");
    DetectOptions options;
    options.max_proposals = std::numeric_limits<int>::max();  // the map's input: every box
    options.want_probability_map = false;
    const Status st = run.FirstError(which, run.ForEachFrame(which, [&](int i, const Sample& s) {
      MapSuperpixels superpixels;
      auto detection = detector.Detect(s.image, options, &superpixels);
      if (!detection.ok()) return detection.status();
      std::vector<ScoredBox> fused;
      fused.reserve(detection->proposals.size());
      for (const Proposal& p : detection->proposals) fused.push_back({p.box, p.fused});
      return isolation.AddFrame(i, s, superpixels, fused);
    }));
    if (!st.ok()) return st.WithContext("calibrating obstacle scores");
  }
  const int chosen = isolation.Best();
  bundle.params.probability_map.isolation.exponent = isolation.exponent(chosen);
  parts["map_isolation"] = {{"learned", true},
                            {"trained", true},
                            {"fit", run.options().fit_map_isolation},
                            {"folds", kFolds},
                            {"fold_layout", FoldLayoutName(run.options().fold_layout)}};
  parts["map_isolation"].update(isolation.ToJson());
  run.Say("map isolation exponent " + std::to_string(isolation.exponent(chosen)));

  std::vector<double> evidence;
  std::vector<int> labels;
  for (const auto& [e, label] : isolation.Components(chosen))
    evidence.push_back(e), labels.push_back(label);
  auto fitted = FitObstacleCalibration(evidence, labels);
  if (!fitted.ok()) {
    // Not an untrained learned part but data without the contrast to fit (e.g. a handful of
    // frames on which every component is an obstacle): said here and recorded, and the bundle's
    // scores stay the raw evidence, as documented for uncalibrated bundles.
    run.Say("obstacle scores NOT calibrated: " + fitted.status().message() +
            "; obstacles report their raw evidence as score");
    bundle.params.obstacle_calibration = ObstacleCalibration{};
    parts["calibration"] = {{"learned", true},
                            {"trained", false},
                            {"reason", fitted.status().message()},
                            {"fold_layout", FoldLayoutName(run.options().fold_layout)},
                            {"components", evidence.size()}};
    return Status::Ok();
  }
  bundle.params.obstacle_calibration = *fitted;
  parts["calibration"] = {{"learned", true},
                          {"trained", true},
                          {"folds", kFolds},
                          {"fold_layout", FoldLayoutName(run.options().fold_layout)},
                          {"components", fitted->samples},
                          {"on_obstacles", fitted->positives}};
  return Status::Ok();
}

// The manifest's record of one regressor ("ordr" or "obdr"): what it learned from and how.
nlohmann::json RegressorPartRecord(const std::string& name, const TrainOptions& options,
                                   const Regressors& regressors, int num_features,
                                   const ClassifierFolds& folds) {
  const bool ordr = name == "ordr";
  const ForestParams forest = RegressorForest(options);
  return {{"learned", true},
          {"trained", true},
          {"samples", ordr ? regressors.ordr_samples : regressors.obdr_samples},
          {"trees", forest.num_trees},
          {"mtry", forest.max_features},
          {"min_leaf", forest.min_leaf_size},
          {"hard_negatives", options.mine_hard_negatives ? "mined" : "objectness"},
          {"negatives_per_range",
           ordr ? options.selection.ordr_negatives : options.selection.obdr_negatives},
          {"negative_bags", options.selection.negative_bags},
          {"hard_fraction", options.selection.hard_fraction},
          {"pasted_copies", options.pasted_copies},
          {"features", num_features},
          {"maps", folds.enabled ? "out_of_fold" : "in_sample"},
          {"fold_layout", FoldLayoutName(options.fold_layout)}};
}

// The manifest's "training" record: the data, the frames and samples, every part's record and
// the run's seconds and peak memory.
nlohmann::json TrainingRecord(const TrainingRun& run, const Survey& survey,
                              const RegressorSamples& samples, const Regressors& regressors,
                              const nlohmann::json& parts, const nlohmann::json& seconds) {
  const TrainOptions& options = run.options();
  const int n = static_cast<int>(survey.usable.size());
  const ForestParams forest = RegressorForest(options);
  nlohmann::json data = nlohmann::json::array({options.data_root});
  for (const std::string& root : options.more_data) data.push_back(root);
  return {{"data", options.more_data.empty() ? nlohmann::json(options.data_root) : data},
          {"format", run.format()},
          {"data_terms", options.data_terms},
          {"split", options.split},
          {"frames", n},
          {"skipped_frames", SkippedFramesToJson(survey.skipped)},
          {"frame_size", {survey.width, survey.height}},
          {"obstacles", survey.footprints.size()},
          {"regions_from", options.regions},
          {"seed", options.seed},
          {"classifier_frames", ClassifierFrames(run, survey).size()},
          {"mean_proposals_per_frame", static_cast<double>(samples.proposals) / n},
          {"ordr_samples", regressors.ordr_samples},
          {"obdr_samples", regressors.obdr_samples},
          {"parts", parts},
          {"regressor",
           {{"trees", forest.num_trees},
            {"mtry", forest.max_features},
            {"min_leaf", forest.min_leaf_size}}},
          {"peak_rss_mb", PeakRssMb()},
          {"seconds", seconds}};
}

}  // namespace

cv::Mat1i LabelMap(const Sample& sample) {
  cv::Mat1i labels(sample.image.size(), 0);
  labels.setTo(1, sample.road);
  // Void (LAF instanceIds < 1000, the mask benchmarks' 255) stays void in every target (§3.4):
  // the ego-vehicle hood and the rectification border are no object boundaries.
  if (!sample.ignore.empty()) labels.setTo(kIgnoreLabel, sample.ignore);
  for (std::size_t i = 0; i < sample.instances.size(); ++i) {
    const ObstacleInstance& inst = sample.instances[i];
    const Box b = ClipToImage(inst.box, labels.cols, labels.rows);
    if (b.empty() || inst.mask.size() != cv::Size(inst.box.w, inst.box.h)) continue;
    const cv::Rect local(b.x - inst.box.x, b.y - inst.box.y, b.w, b.h);
    labels(b.rect()).setTo(static_cast<int>(2 + i), inst.mask(local));
  }
  return labels;
}

Result<ModelBundle> TrainModel(const TrainOptions& options) {
  // Each negative bag is a forest of its own (FitBaggedRegressor): checked before any work.
  if (options.selection.negative_bags > options.regressor.num_trees)
    return Status::InvalidArgument(
        "--negative-bags " + std::to_string(options.selection.negative_bags) +
        " is more than the regressors' " + std::to_string(options.regressor.num_trees) +
        " trees: every bag needs a tree of its own");
  TrainingRun run(options);
  if (Status st = run.Open(); !st.ok()) return st;
  ModelBundle bundle;
  bundle.params = options.params;
  nlohmann::json parts = nlohmann::json::object();

  run.StartStep();
  auto survey = SurveyFrames(run);
  if (!survey.ok()) return survey.status();
  if (Status st = DeriveGeometry(run, *survey, bundle, parts); !st.ok()) return st;
  run.EndStep("survey");

  ClassifierFolds folds(options.out_of_fold_maps, run.num_frames(), survey->usable,
                        ClassifierFrames(run, *survey), options.fold_layout, run.FrameSources());
  if (folds.enabled) folds.upstream.fill(bundle);  // parameters, geometry; classifiers below

  run.StartStep();
  if (Status st = TrainEdgeSource(run, *survey, bundle, folds, parts); !st.ok()) return st;
  run.EndStep("edges");

  run.StartStep();
  if (Status st = TrainOcclusionClassifier(run, *survey, bundle, folds, parts); !st.ok()) return st;
  run.EndStep("occlusion");

  auto trained = TrainRegressors(run, *survey, bundle, folds);
  if (!trained.ok()) return trained.status();
  bundle.ordr = std::move(trained->regressors.ordr);
  bundle.obdr = std::move(trained->regressors.obdr);
  const RegressorSamples& samples = trained->samples;
  const Regressors& regressors = trained->regressors;  // its sample counts
  for (const char* name : {"ordr", "obdr"})
    parts[name] = RegressorPartRecord(name, options, regressors, bundle.ordr.num_features(), folds);

  run.StartStep();
  run.Say("calibrating obstacle scores and fitting the map's isolation (2-fold)");
  if (Status st = CalibrateObstacleScores(run, *survey, samples, folds, bundle, parts); !st.ok())
    return st;
  run.EndStep("calibration");

  nlohmann::json seconds = run.seconds();
  seconds["total"] = SecondsSince(run.started());
  bundle.training = TrainingRecord(run, *survey, samples, regressors, parts, seconds);
  bundle.version = "tod-" + NowIso8601().substr(0, 10) + "-seed" + std::to_string(options.seed);
  run.Say("trained in " + std::to_string(static_cast<int>(seconds["total"].get<double>())) + " s");
  return bundle;
}

}  // namespace tod
