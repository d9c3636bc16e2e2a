#include "core/pipeline/trainer.h"

#include <atomic>
#include <chrono>
#include <mutex>

#include "core/edges/edge_labels.h"
#include "core/pipeline/dataset_factory.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"

namespace tod {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Rows of `all` selected by `indices`, as a proposal subset for feature extraction.
ProposalSet Subset(const ProposalSet& all, const std::vector<int>& indices) {
  ProposalSet out;
  for (int i : indices) {
    out.boxes.push_back(all.boxes[i]);
    out.layer.push_back(all.layer[i]);
  }
  return out;
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
  auto say = [&](const std::string& line) {
    if (options.progress) options.progress(line);
  };
  const auto started = Clock::now();
  auto selection = SelectFrames(
      {options.data_root, options.split, options.format, options.split_file, options.max_frames});
  if (!selection.ok()) return selection.status();
  const Dataset& dataset = *selection->dataset;
  const std::string& format = selection->format;
  const std::vector<int>& frame_ids = selection->frames;
  const int n = static_cast<int>(frame_ids.size());

  // 1. Read the split (kept in memory: every later step visits every frame).
  say("reading " + std::to_string(n) + " training frames from " + options.data_root);
  std::vector<Sample> frames(n);
  const std::vector<Status> errors = ParallelFor(n, options.threads, [&](int i) -> Status {
    auto s = dataset.Load(frame_ids[i]);
    if (!s.ok()) return s.status();
    frames[i] = std::move(*s);
    return Status::Ok();
  });
  for (const Status& e : errors)
    if (!e.ok()) return e;
  const int width = frames.front().image.cols, height = frames.front().image.rows;
  for (const Sample& s : frames)
    if (s.image.cols != width || s.image.rows != height)
      return Status::InvalidArgument(s.image_path +
                                     ": frame size differs from the split's first frame (" +
                                     std::to_string(width) + "x" + std::to_string(height) + ")");

  // 2. Multilayer regions and the size filter from the training obstacles (§1.4, §4.3).
  ModelBundle bundle;
  bundle.params = options.params;
  std::vector<ObstacleFootprint> footprints;
  std::vector<Box> obstacle_boxes;
  for (const Sample& s : frames)
    for (const ObstacleInstance& inst : s.instances) {
      footprints.push_back({inst.box, inst.pixel_count()});
      obstacle_boxes.push_back(inst.box);
    }
  say(std::to_string(footprints.size()) + " training obstacles");
  if (options.regions == "laf2020") {
    bundle.regions = Laf2020Regions().ScaledTo(width, height);
    bundle.size_filter = SizeFilter::Laf2020();
    if (width != 2048 || height != 1024) bundle.size_filter = SizeFilter::Derive(obstacle_boxes);
  } else if (options.regions == "auto") {
    RegionParams region_params = options.params.regions;
    region_params.seed = options.seed;
    auto regions = DeriveMultilayerRegions(footprints, width, height, region_params);
    if (!regions.ok()) return regions.status();
    bundle.regions = *regions;
    bundle.size_filter = SizeFilter::Derive(obstacle_boxes);
  } else {
    return Status::InvalidArgument("--regions must be auto or laf2020, got '" + options.regions +
                                   "'");
  }
  bundle.size_filter.enabled = options.params.size_filter;
  for (int k = 0; k < bundle.regions.num_layers(); ++k) {
    const Box& r = bundle.regions.layers[k];
    say("R" + std::to_string(k + 1) + " = [" + std::to_string(r.x) + ", " + std::to_string(r.y) +
        ", " + std::to_string(r.w) + " x " + std::to_string(r.h) + "]");
  }

  // 3. Base edge source (§3.4 step 1).
  const std::vector<int> classifier_ids = SpreadIndices(n, options.classifier_frames);
  const Box r1 = bundle.regions.layers.front();
  auto t0 = Clock::now();
  bundle.edge_kind = options.edge_source;
  if (options.edge_source == "pixel_forest") {
    std::vector<EdgeTrainingFrame> edge_frames;
    for (int i : classifier_ids)
      edge_frames.push_back(
          {frames[i].image(r1.rect()).clone(), LabelMap(frames[i])(r1.rect()).clone()});
    PixelEdgeParams edge_params = options.edge_params;
    edge_params.forest.seed = options.seed;
    say("training the pixel edge classifier on " + std::to_string(edge_frames.size()) + " frames");
    auto classifier = PixelEdgeClassifier::TryTrain(edge_frames, edge_params);
    if (!classifier.ok())
      return classifier.status().WithContext("training the pixel edge classifier");
    bundle.params.prior_correction.edge_odds =
        options.prior_correction ? classifier->sampled_odds_scale() : 1.0;
    bundle.edges = std::make_shared<PixelEdgeClassifier>(std::move(*classifier));
  } else if (options.edge_source == "gradient") {
    bundle.edges = CreateGradientEdgeSource(options.params.gradient_edges);
  } else if (options.edge_source == "sed") {
    auto sed = CreateSedEdgeSource(options.sed_model);
    if (!sed.ok()) return sed.status();
    bundle.edges = std::shared_ptr<const EdgeSource>(std::move(*sed));
  } else {
    return Status::InvalidArgument("unknown edge source '" + options.edge_source +
                                   "' (pixel_forest, gradient, sed)");
  }
  const double edge_seconds = SecondsSince(t0);

  // 4. Occlusion classifier on superpixel boundaries (§3.4 steps 2-5).
  t0 = Clock::now();
  std::vector<OcclusionTrainingFrame> occlusion_frames(classifier_ids.size());
  (void)ParallelFor(static_cast<int>(classifier_ids.size()), options.threads, [&](int j) {
    const Sample& s = frames[classifier_ids[j]];
    OcclusionEdges oaocc = ComputeOcclusionEdges(s.image, bundle.regions, *bundle.edges, nullptr,
                                                 bundle.params, /*enhance=*/true);
    occlusion_frames[j] = {oaocc.crop.clone(), oaocc.enhanced, oaocc.superpixels,
                           LabelMap(s)(oaocc.r1.rect()).clone()};
    return Status::Ok();
  });
  OcclusionParams occlusion_params = options.occlusion_params;
  occlusion_params.forest.seed = options.seed;
  say("training the occlusion classifier on " + std::to_string(occlusion_frames.size()) +
      " frames");
  auto occlusion = OcclusionClassifier::Fit(occlusion_frames, occlusion_params);
  if (!occlusion.ok()) return occlusion.status().WithContext("training the occlusion classifier");
  bundle.occlusion = std::move(*occlusion);
  bundle.params.prior_correction.occlusion_odds =
      options.prior_correction ? bundle.occlusion.sampled_odds_scale() : 1.0;
  occlusion_frames.clear();
  const double occlusion_seconds = SecondsSince(t0);

  // 5. ORDR and OBDR on the full test-time proposal set of every frame (§6).
  t0 = Clock::now();
  const std::vector<int> limits = bundle.regions.RangeLimits();
  std::vector<cv::Mat1f> ordr_rows(n), obdr_rows(n);
  std::vector<std::vector<float>> ordr_targets(n), obdr_targets(n);
  std::vector<long long> proposal_counts(n, 0);
  std::atomic<int> done{0};
  std::mutex say_mutex;
  (void)ParallelFor(n, options.threads, [&](int i) {
    const Sample& s = frames[i];
    if (cv::countNonZero(s.road) > 0) {
      const OcclusionEdges oaocc = ComputeOcclusionEdges(s.image, bundle.regions, *bundle.edges,
                                                         &bundle.occlusion, bundle.params, true);
      const ProposalOptions popts =
          DetectorProposalOptions(bundle.params, bundle.regions.num_layers());
      const ProposalSet all =
          ProposeBoxes(oaocc, bundle.regions, bundle.params.boxes, popts, bundle.size_filter);
      proposal_counts[i] = static_cast<long long>(all.boxes.size());
      auto selected = SelectTrainingSamples(all.boxes, s, limits, options.selection,
                                            options.seed * 1000003ULL + static_cast<unsigned>(i));
      if (selected.ok()) {
        ordr_rows[i] = ComputeProposalFeatures(s.image, oaocc, bundle.regions,
                                               Subset(all, selected->ordr_indices));
        obdr_rows[i] = ComputeProposalFeatures(s.image, oaocc, bundle.regions,
                                               Subset(all, selected->obdr_indices));
        ordr_targets[i] = selected->ordr_targets;
        obdr_targets[i] = selected->obdr_targets;
      }
    }
    const int finished = ++done;
    if (finished % 10 == 0 || finished == n) {
      std::lock_guard lock(say_mutex);
      say("proposals and samples: " + std::to_string(finished) + "/" + std::to_string(n) +
          " frames");
    }
    return Status::Ok();
  });
  auto stack = [](const std::vector<cv::Mat1f>& parts,
                  const std::vector<std::vector<float>>& targets, cv::Mat1f& rows,
                  std::vector<float>& y) {
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (parts[i].empty()) continue;
      rows.push_back(parts[i]);
      y.insert(y.end(), targets[i].begin(), targets[i].end());
    }
  };
  cv::Mat1f ordr_x, obdr_x;
  std::vector<float> ordr_y, obdr_y;
  stack(ordr_rows, ordr_targets, ordr_x, ordr_y);
  stack(obdr_rows, obdr_targets, obdr_x, obdr_y);
  if (ordr_x.rows < 10 || obdr_x.rows < 10)
    return Status::InvalidArgument(
        options.data_root + ": too few training samples for the regressors (" +
        std::to_string(ordr_x.rows) + " ORDR, " + std::to_string(obdr_x.rows) +
        " OBDR); need frames with road and obstacles");
  const double proposal_seconds = SecondsSince(t0);
  t0 = Clock::now();
  ForestParams forest = options.regressor;
  forest.seed = options.seed;
  forest.threads = options.threads;
  say("training ORDR on " + std::to_string(ordr_x.rows) + " samples");
  bundle.ordr = RandomForest::Train(ordr_x, ordr_y, forest);
  forest.seed = options.seed + 1;
  say("training OBDR on " + std::to_string(obdr_x.rows) + " samples");
  bundle.obdr = RandomForest::Train(obdr_x, obdr_y, forest);
  const double regressor_seconds = SecondsSince(t0);

  long long proposals_total = 0;
  for (long long c : proposal_counts) proposals_total += c;
  bundle.training = {{"data", options.data_root},
                     {"format", format},
                     {"split", options.split},
                     {"frames", n},
                     {"frame_size", {width, height}},
                     {"obstacles", footprints.size()},
                     {"regions_from", options.regions},
                     {"seed", options.seed},
                     {"classifier_frames", classifier_ids.size()},
                     {"mean_proposals_per_frame", static_cast<double>(proposals_total) / n},
                     {"ordr_samples", ordr_x.rows},
                     {"obdr_samples", obdr_x.rows},
                     {"regressor",
                      {{"trees", forest.num_trees},
                       {"mtry", forest.max_features},
                       {"min_leaf", forest.min_leaf_size}}},
                     {"seconds",
                      {{"edges", edge_seconds},
                       {"occlusion", occlusion_seconds},
                       {"proposals_and_samples", proposal_seconds},
                       {"regressors", regressor_seconds},
                       {"total", SecondsSince(started)}}}};
  bundle.version = "tod-" + NowIso8601().substr(0, 10) + "-seed" + std::to_string(options.seed);
  say("trained in " + std::to_string(static_cast<int>(SecondsSince(started))) + " s");
  return bundle;
}

}  // namespace tod
