#include "core/training/training_regressors.h"

#include <algorithm>
#include <atomic>
#include <string>

#include "core/data/pasted_obstacles.h"
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

// The rows of the own boxes `truth` (features `x`, one row each), appended to both regressors'
// rows as positives of every bag, with the targets the selection gives (mask IoU, or box IoU with
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
    rows.ordr_bags.push_back(SelectedSamples::kEveryBag);
    rows.obdr_bags.push_back(SelectedSamples::kEveryBag);
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
// `miner`, by the miner's fused score; the selected samples' features and targets. With
// `positives_only` (a pasted copy: its negatives would be the frame's road again) the negatives
// are dropped before any feature is computed.
Result<FrameRows> RegressorRowsOfFrame(const Sample& s, const ModelBundle& bundle,
                                       const ModelBundle& upstream, const ModelBundle* miner,
                                       const SampleSelectionParams& selection, std::uint64_t seed,
                                       bool positives_only, bool truth_boxes) {
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
  rows.ordr_bags = std::move(selected->ordr_bags);
  rows.obdr_bags = std::move(selected->obdr_bags);
  rows.proposals = static_cast<long long>(all.boxes.size());
  const cv::Mat1f truth_rows = x.rowRange(static_cast<int>(distinct.size()), x.rows);
  if (Status st = AppendTruthRows(s, truth, truth_rows, selection, rows); !st.ok()) return st;
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
                                           /*positives_only=*/false, options.truth_box_positives);
          if (!rows.ok()) return rows.status();
          const std::vector<const ObstacleCutout*> donors =
              options.pasted_copies > 0 ? DonorsFor(i, survey, folds)
                                        : std::vector<const ObstacleCutout*>{};
          for (int copy = 1; copy <= options.pasted_copies && !donors.empty(); ++copy) {
            const std::uint64_t copy_seed = seed + 0x9E3779B97F4A7C15ULL * copy;
            Sample pasted = PasteObstacles(s, donors, copy_seed, options.paste);
            if (pasted.instances.size() == s.instances.size()) continue;  // no place was free
            VoidOwnObstacles(pasted, s.instances.size());
            auto more =
                RegressorRowsOfFrame(pasted, bundle, upstream, miner, options.selection, copy_seed,
                                     /*positives_only=*/true, options.truth_box_positives);
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

}  // namespace

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
