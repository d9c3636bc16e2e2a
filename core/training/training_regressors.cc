#include "core/training/training_regressors.h"

#include <algorithm>
#include <atomic>
#include <string>

#include "core/features/mask_iou.h"
#include "core/features/sample_selection.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/probability_map.h"
#include "core/pipeline/proposal_features.h"
#include "core/pipeline/proposal_regression.h"
#include "core/training/truth_boxes.h"

namespace tod::training {
namespace {

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

// The regressors' rows of one frame.
struct FrameRows {
  cv::Mat1f ordr, obdr;
  std::vector<float> ordr_targets, obdr_targets;
  long long proposals = 0;
};

// The rows of the own boxes `truth` (features `x`, one row each), appended to both regressors'
// rows as positives, with the targets the selection gives (mask IoU, or box IoU with
// SampleSelectionParams::box_iou_target).
Status AppendTruthRows(const Sample& s, const ProposalSet& truth, const cv::Mat1f& x,
                       const SampleSelectionParams& selection, FrameRows& rows) {
  if (truth.boxes.empty()) return Status::Ok();
  auto table = MaskIoUTable::Build(s.instances);
  if (!table.ok()) return table.status();
  for (const ScoredBox& b : truth.boxes) {
    const float target = static_cast<float>(selection.box_iou_target ? table->MaxBoxIoU(b.box)
                                                                     : table->MaxIoU(b.box));
    rows.ordr_targets.push_back(target);
    rows.obdr_targets.push_back(target);
  }
  rows.ordr.push_back(x);
  rows.obdr.push_back(x);
  return Status::Ok();
}

// The rows of `measured` (features of distinct proposals) that `indices` (proposal indices) ask
// for, in their order; row_of[i] is proposal i's row in `measured`.
cv::Mat1f PickRows(const cv::Mat1f& measured, const std::vector<int>& indices,
                   const std::vector<int>& row_of) {
  cv::Mat1f out(static_cast<int>(indices.size()), measured.cols);
  for (std::size_t j = 0; j < indices.size(); ++j)
    measured.row(row_of[indices[j]]).copyTo(out.row(static_cast<int>(j)));
  return out;
}

// §6 on one frame: its proposals (maps by `upstream`'s classifiers), ranked by objectness or, with
// `miner`, by the miner's fused score; the selected samples' features and targets.
Result<FrameRows> RegressorRowsOfFrame(const Sample& s, const ModelBundle& bundle,
                                       const ModelBundle& upstream, const ModelBundle* miner,
                                       const SampleSelectionParams& selection, std::uint64_t seed,
                                       bool truth_boxes) {
  const Result<OcclusionEdges> computed = ComputeOcclusionEdges(
      s.image, bundle.regions, *upstream.edges, &upstream.occlusion, upstream.params, true);
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
  // The two selections share their positives and may share negatives: every distinct proposal
  // is measured once, beside the own boxes, on one set of R1's colour tables.
  std::vector<int> distinct = selected->ordr_indices;
  distinct.insert(distinct.end(), selected->obdr_indices.begin(), selected->obdr_indices.end());
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  ProposalSet measured = Subset(all, distinct);
  const ProposalSet truth =
      truth_boxes
          ? TruthBoxes(
                s.instances, oaocc, bundle.regions, bundle.params.boxes,
                DetectorProposalOptions(bundle.params, bundle.regions.num_layers()).multistride)
          : ProposalSet{};
  measured.boxes.insert(measured.boxes.end(), truth.boxes.begin(), truth.boxes.end());
  measured.layer.insert(measured.layer.end(), truth.layer.begin(), truth.layer.end());
  const cv::Mat1f x =
      ComputeProposalFeatures(s.image, oaocc, bundle.regions, measured,
                              FeatureOptionsForFrame(bundle, s.image.cols, s.image.rows));
  std::vector<int> row_of(all.boxes.size(), -1);
  for (std::size_t r = 0; r < distinct.size(); ++r) row_of[distinct[r]] = static_cast<int>(r);

  FrameRows rows;
  rows.ordr = PickRows(x, selected->ordr_indices, row_of);
  rows.obdr = PickRows(x, selected->obdr_indices, row_of);
  rows.ordr_targets = std::move(selected->ordr_targets);
  rows.obdr_targets = std::move(selected->obdr_targets);
  rows.proposals = static_cast<long long>(all.boxes.size());
  const cv::Mat1f truth_rows = x.rowRange(static_cast<int>(distinct.size()), x.rows);
  if (Status st = AppendTruthRows(s, truth, truth_rows, selection, rows); !st.ok()) return st;
  return rows;
}

// With `miner` (a bundle with trained regressors), the negatives' "hard" share is drawn from the
// proposals the miner's fused score puts above selection.hard_objectness instead of by
// objectness (TrainOptions::mine_hard_negatives).
Result<RegressorSamples> CollectRegressorSamples(TrainingRun& run, const Survey& survey,
                                                 const ModelBundle& bundle,
                                                 const ClassifierFolds& folds,
                                                 const ModelBundle* miner = nullptr) {
  const TrainOptions& options = run.options();
  const int n = run.num_frames();
  RegressorSamples out;
  out.ordr_rows.resize(n), out.obdr_rows.resize(n);
  out.ordr_targets.resize(n), out.obdr_targets.resize(n);
  std::vector<long long> proposals(n, 0);
  std::atomic<int> done{0};
  const Status st =
      run.FirstError(survey.usable, run.ForEachFrame(survey.usable, [&](int i, const Sample& s) {
        if (cv::countNonZero(s.road) > 0) {
          const ModelBundle& upstream = folds.For(bundle, i);
          const std::uint64_t seed = options.seed * 1000003ULL + static_cast<unsigned>(i);
          auto rows = RegressorRowsOfFrame(s, bundle, upstream, miner, SampleSelectionParams{},
                                           seed, options.truth_box_positives);
          if (!rows.ok()) return rows.status();
          proposals[i] = rows->proposals;
          out.ordr_rows[i] = std::move(rows->ordr);
          out.obdr_rows[i] = std::move(rows->obdr);
          out.ordr_targets[i] = std::move(rows->ordr_targets);
          out.obdr_targets[i] = std::move(rows->obdr_targets);
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

// One regressor (the paper's forest) on the samples of the frames `in_fold(i)` accepts.
Result<RandomForest> FitRegressor(const std::vector<cv::Mat1f>& parts,
                                  const std::vector<std::vector<float>>& targets,
                                  const std::function<bool(int)>& in_fold,
                                  const ForestParams& forest, int& samples) {
  constexpr int kMinSamples = 10;
  cv::Mat1f x;
  std::vector<float> y;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].empty() || !in_fold(static_cast<int>(i))) continue;
    for (int r = 0; r < parts[i].rows; ++r) {
      x.push_back(parts[i].row(r));
      y.push_back(targets[i][r]);
    }
  }
  samples = x.rows;
  if (x.rows < kMinSamples)
    return Status::InvalidArgument("too few training samples (" + std::to_string(x.rows) +
                                   ", need " + std::to_string(kMinSamples) +
                                   "); need frames with obstacles and free space");
  return RandomForest::Fit(x, y, forest);
}

}  // namespace

Result<Regressors> TrainRegressorPair(const RegressorSamples& samples,
                                      const std::function<bool(int)>& in_fold,
                                      ForestParams forest) {
  Regressors out;
  auto ordr =
      FitRegressor(samples.ordr_rows, samples.ordr_targets, in_fold, forest, out.ordr_samples);
  if (!ordr.ok()) return ordr.status().WithContext("ORDR");
  forest.seed += 1;
  auto obdr =
      FitRegressor(samples.obdr_rows, samples.obdr_targets, in_fold, forest, out.obdr_samples);
  if (!obdr.ok()) return obdr.status().WithContext("OBDR");
  out.ordr = std::move(*ordr);
  out.obdr = std::move(*obdr);
  return out;
}

ForestParams RegressorForest(const TrainOptions& options) {
  // The Liaw-Wiener defaults: mtry 6 of 20, leaves of at least 5 samples (other values were
  // measured and removed: docs/findings.md#regressor-mtry-min-leaf-and-hard-fraction).
  ForestParams forest{.num_trees = options.regressor_trees, .max_features = 6, .min_leaf_size = 5};
  forest.seed = options.seed;
  forest.threads = options.threads;
  return forest;
}
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

}  // namespace tod::training
