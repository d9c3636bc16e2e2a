#include "core/features/sample_selection.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace tod {
namespace {

// Uniform integer in [0, n) by rejection, so the draws are the same on every standard library
// (std::uniform_int_distribution and std::shuffle are implementation-defined).
std::uint64_t UniformBelow(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t limit = std::mt19937_64::max() - std::mt19937_64::max() % n;
  std::uint64_t draw;
  do {
    draw = rng();
  } while (draw >= limit);
  return draw % n;
}

// `count` distinct elements of `pool`, uniformly at random (partial Fisher-Yates).
std::vector<int> DrawWithoutReplacement(std::vector<int> pool, std::size_t count,
                                        std::mt19937_64& rng) {
  count = std::min(count, pool.size());
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t j = i + UniformBelow(rng, pool.size() - i);
    std::swap(pool[i], pool[j]);
  }
  pool.resize(count);
  return pool;
}

// n negatives: round(tau_l * n) from the hard pool, the rest from the easy pool, each topped up
// from the other when short (§6.2 [R]); fewer when both pools together hold fewer than n.
std::vector<int> DrawNegatives(const std::vector<int>& hard, const std::vector<int>& easy, int n,
                               double hard_fraction, std::mt19937_64& rng) {
  const std::size_t wanted = static_cast<std::size_t>(std::max(0, n));
  const std::size_t hard_wanted =
      std::min(wanted, static_cast<std::size_t>(std::lround(hard_fraction * wanted)));
  std::size_t take_hard = std::min(hard_wanted, hard.size());
  std::size_t take_easy = std::min(wanted - hard_wanted, easy.size());
  std::size_t missing = wanted - take_hard - take_easy;
  const std::size_t extra_hard = std::min(missing, hard.size() - take_hard);
  take_hard += extra_hard;
  missing -= extra_hard;
  take_easy += std::min(missing, easy.size() - take_easy);

  std::vector<int> drawn = DrawWithoutReplacement(hard, take_hard, rng);
  const std::vector<int> easy_drawn = DrawWithoutReplacement(easy, take_easy, rng);
  drawn.insert(drawn.end(), easy_drawn.begin(), easy_drawn.end());
  return drawn;
}

Status ValidateSelectionInput(const Sample& gt, const std::vector<int>& range_limits,
                              const SampleSelectionParams& params) {
  const std::string where = "SelectTrainingSamples(sample '" + gt.name + "'): ";
  if (range_limits.size() < 2) {
    return Status::InvalidArgument(where + "range_limits needs K + 1 >= 2 row limits, got " +
                                   std::to_string(range_limits.size()));
  }
  for (std::size_t i = 1; i < range_limits.size(); ++i) {
    if (range_limits[i] >= range_limits[i - 1]) {
      return Status::InvalidArgument(where +
                                     "range_limits must be strictly decreasing (y_1 > "
                                     "... > y_{K+1}), but entry " +
                                     std::to_string(i) + " is " + std::to_string(range_limits[i]) +
                                     " after " + std::to_string(range_limits[i - 1]));
    }
  }
  const std::size_t num_ranges = range_limits.size() - 1;
  const auto check_counts = [&](const std::vector<int>& counts, const char* field) -> Status {
    if (counts.size() != num_ranges) {
      return Status::InvalidArgument(where + "params." + field + " has " +
                                     std::to_string(counts.size()) + " entries but there are " +
                                     std::to_string(num_ranges) + " vertical ranges");
    }
    if (std::any_of(counts.begin(), counts.end(), [](int c) { return c < 0; })) {
      return Status::InvalidArgument(where + "params." + field + " has a negative count");
    }
    return Status::Ok();
  };
  if (Status s = check_counts(params.ordr_negatives, "ordr_negatives"); !s.ok()) return s;
  if (Status s = check_counts(params.obdr_negatives, "obdr_negatives"); !s.ok()) return s;
  if (Status s = check_counts(params.positives, "positives"); !s.ok()) return s;
  if (!(params.hard_fraction >= 0.0 && params.hard_fraction <= 1.0)) {
    return Status::InvalidArgument(where + "params.hard_fraction must lie in [0, 1]");
  }
  if (gt.road.empty()) {
    return Status::InvalidArgument(where + "the road mask is empty; categories need it");
  }
  if (!gt.image.empty() && gt.road.size() != gt.image.size()) {
    return Status::InvalidArgument(where + "the road mask size differs from the image size");
  }
  return Status::Ok();
}

}  // namespace

ProposalCategory CategorizeProposal(const Box& box, const MaskIoUTable& obstacles,
                                    const MaskPixelCounter& road,
                                    const MaskPixelCounter& void_pixels,
                                    const SampleSelectionParams& params) {
  if (obstacles.MaxIoU(box) >= params.obstacle_iou) return ProposalCategory::kObstacle;
  const long long scored = box.area() - void_pixels.Count(box);
  if (scored > 0 &&
      static_cast<double>(road.Count(box)) / static_cast<double>(scored) > params.road_fraction) {
    return ProposalCategory::kRoad;
  }
  return ProposalCategory::kBackground;
}

int VerticalRangeIndex(int row, const std::vector<int>& range_limits) {
  const int num_ranges = static_cast<int>(range_limits.size()) - 1;
  for (int k = 0; k + 1 < num_ranges; ++k) {
    if (row > range_limits[k + 1]) return k;  // (y_{k+2}, y_{k+1}] and everything below y_1
  }
  return std::max(0, num_ranges - 1);  // the closed top range and everything above it
}

namespace {

// What selection needs of each proposal: its best mask IoU with an obstacle, its category and
// its vertical range.
struct ProposalLabels {
  std::vector<double> max_iou;
  std::vector<ProposalCategory> category;
  std::vector<int> range;
};

ProposalLabels LabelProposals(const std::vector<ScoredBox>& proposals, const Sample& gt,
                              const MaskIoUTable& obstacles, const std::vector<int>& range_limits,
                              const SampleSelectionParams& params) {
  const MaskPixelCounter road(gt.road);
  const MaskPixelCounter void_pixels =
      gt.ignore.empty() ? MaskPixelCounter() : MaskPixelCounter(gt.ignore);
  ProposalLabels labels;
  labels.max_iou.reserve(proposals.size());
  labels.category.reserve(proposals.size());
  labels.range.reserve(proposals.size());
  for (const ScoredBox& proposal : proposals) {
    const Box& box = proposal.box;
    labels.max_iou.push_back(obstacles.MaxIoU(box));
    labels.category.push_back(CategorizeProposal(box, obstacles, road, void_pixels, params));
    labels.range.push_back(VerticalRangeIndex(BottomRow(box), range_limits));
  }
  return labels;
}

// Positives: per GT obstacle, the n+_k proposals of all of B^I with the highest IoU to it
// (IoU > 0), k = range of the obstacle's bottom; ties keep the lower proposal index. In order of
// the obstacles, each proposal once.
std::vector<int> SelectPositives(const std::vector<ScoredBox>& proposals, const Sample& gt,
                                 const MaskIoUTable& obstacles,
                                 const std::vector<int>& range_limits,
                                 const SampleSelectionParams& params) {
  std::vector<int> positives;
  std::vector<char> is_positive(proposals.size(), 0);
  for (int o = 0; o < obstacles.num_instances(); ++o) {
    const int k = VerticalRangeIndex(BottomRow(gt.instances[o].box), range_limits);
    std::vector<std::pair<double, int>> overlapping;  // (IoU, proposal index)
    for (int i = 0; i < static_cast<int>(proposals.size()); ++i) {
      const double iou = obstacles.IoU(proposals[i].box, o);
      if (iou > 0.0) overlapping.emplace_back(iou, i);
    }
    const std::size_t take =
        std::min(overlapping.size(), static_cast<std::size_t>(params.positives[k]));
    std::partial_sort(overlapping.begin(), overlapping.begin() + take, overlapping.end(),
                      [](const auto& a, const auto& b) {
                        return a.first != b.first ? a.first > b.first : a.second < b.second;
                      });
    for (std::size_t j = 0; j < take; ++j) {
      const int index = overlapping[j].second;
      if (!is_positive[index]) {
        is_positive[index] = 1;
        positives.push_back(index);
      }
    }
  }
  return positives;
}

// Draws the negatives of one regressor after another from one random stream, so that the draws
// depend only on the seed and the order of the calls.
class NegativeSampler {
 public:
  NegativeSampler(const std::vector<ScoredBox>& proposals, const ProposalLabels& labels,
                  const std::vector<int>& positives, int num_ranges,
                  const SampleSelectionParams& params, std::uint64_t seed)
      : proposals_(proposals),
        labels_(labels),
        num_ranges_(num_ranges),
        params_(params),
        rng_(seed),
        is_positive_(proposals.size(), 0) {
    for (const int i : positives) is_positive_[i] = 1;
  }

  // Per vertical range k, counts[k] negatives of `wanted` that are not positives, hard ones
  // (objectness above hard_objectness) and easy ones as DrawNegatives shares them. Each call
  // draws afresh from one random stream, so ORDR's and OBDR's draws are independent.
  std::vector<int> Draw(ProposalCategory wanted, const std::vector<int>& counts) {
    std::vector<int> negatives;
    for (int k = 0; k < num_ranges_; ++k) {
      std::vector<int> hard, easy;
      for (int i = 0; i < static_cast<int>(proposals_.size()); ++i) {
        if (labels_.range[i] != k || labels_.category[i] != wanted || is_positive_[i] ||
            labels_.max_iou[i] >= params_.obstacle_iou) {
          continue;
        }
        (proposals_[i].score > params_.hard_objectness ? hard : easy).push_back(i);
      }
      const std::vector<int> drawn =
          DrawNegatives(hard, easy, counts[k], params_.hard_fraction, rng_);
      negatives.insert(negatives.end(), drawn.begin(), drawn.end());
    }
    return negatives;
  }

 private:
  const std::vector<ScoredBox>& proposals_;
  const ProposalLabels& labels_;
  const int num_ranges_;
  const SampleSelectionParams& params_;
  std::mt19937_64 rng_;
  std::vector<char> is_positive_;
};

}  // namespace

Result<SelectedSamples> SelectTrainingSamples(const std::vector<ScoredBox>& proposals,
                                              const Sample& gt,
                                              const std::vector<int>& range_limits,
                                              const SampleSelectionParams& params,
                                              std::uint64_t seed) {
  if (Status s = ValidateSelectionInput(gt, range_limits, params); !s.ok()) return s;
  Result<MaskIoUTable> table = MaskIoUTable::Build(gt.instances);
  if (!table.ok()) {
    return Status::InvalidArgument("SelectTrainingSamples(sample '" + gt.name +
                                   "'): " + table.status().message());
  }
  const MaskIoUTable& obstacles = *table;
  const ProposalLabels labels = LabelProposals(proposals, gt, obstacles, range_limits, params);
  SelectedSamples out;
  out.positive_indices = SelectPositives(proposals, gt, obstacles, range_limits, params);

  const auto assemble = [&](const std::vector<int>& negatives, std::vector<int>& indices,
                            std::vector<float>& targets) {
    indices = out.positive_indices;
    indices.insert(indices.end(), negatives.begin(), negatives.end());
    targets.reserve(indices.size());
    for (const int i : indices) {
      targets.push_back(static_cast<float>(
          params.box_iou_target ? obstacles.MaxBoxIoU(proposals[i].box) : labels.max_iou[i]));
    }
  };
  // No road label (obstacle-mask benchmarks): road and background cannot be told apart, so
  // every non-obstacle proposal is category (i) and OBDR draws its negatives, independently of
  // ORDR's, from the same pool. The two regressors then differ by their samples only, and the
  // fusion acts as a two-member ensemble instead of adding a background expert.
  // (The two draws are independent: a proposal may be a negative of both.)
  const ProposalCategory obdr_pool = gt.free_space == FreeSpace::kNotObstacle
                                         ? ProposalCategory::kRoad
                                         : ProposalCategory::kBackground;
  NegativeSampler sampler(proposals, labels, out.positive_indices,
                          static_cast<int>(range_limits.size()) - 1, params, seed);
  assemble(sampler.Draw(ProposalCategory::kRoad, params.ordr_negatives), out.ordr_indices,
           out.ordr_targets);
  assemble(sampler.Draw(obdr_pool, params.obdr_negatives), out.obdr_indices, out.obdr_targets);
  return out;
}

}  // namespace tod
