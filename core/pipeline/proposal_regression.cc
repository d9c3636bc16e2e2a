#include "core/pipeline/proposal_regression.h"

#include <algorithm>

#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/parallel.h"
#include "core/pipeline/probability_map.h"
#include "core/pipeline/proposal_features.h"

namespace tod {
namespace {

// Proposals per chunk: large enough that the forest's batched walk stays efficient (each chunk
// walks every tree again), small enough that a deadline is noticed within ~25 ms on real frames
// (features and ORDR cost ~6 us a proposal there).
constexpr std::size_t kProposalsPerChunk = 4096;

// Splits [begin, end) into `threads` contiguous pieces run at once; body(piece_begin, piece_end).
template <typename Body>
void SplitRange(std::size_t begin, std::size_t end, int threads, Body body) {
  const std::size_t n = end - begin;
  const int pieces = static_cast<int>(std::clamp<std::size_t>(n / 64, 1, std::max(1, threads)));
  if (pieces <= 1) {
    body(begin, end);
    return;
  }
  // ParallelFor turns an exception into a Status; the bodies here do not throw (no allocation
  // beyond their own vectors), so an error is a bug worth surfacing.
  for (const Status& s : ParallelFor(pieces, pieces, [&](int p) {
         body(begin + n * p / pieces, begin + n * (p + 1) / pieces);
         return Status::Ok();
       }))
    if (!s.ok()) throw std::runtime_error(s.ToString());
}

}  // namespace

RegressedProposals RegressProposals(const ModelBundle& bundle, const cv::Mat3b& image,
                                    const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                    ProposalSet proposals, StageTimer* timer,
                                    const RegressionLimits& limits, FrameColourTables colour) {
  using Clock = std::chrono::steady_clock;
  RegressedProposals out;
  const std::size_t n = proposals.boxes.size();
  const BoxFeatureOptions feature_options = FeatureOptionsForFrame(bundle, image.cols, image.rows, limits.horizon_shift);
  cv::Mat1f features(static_cast<int>(n), NumBoxFeatures(feature_options), 0.f);
  out.ordr.assign(n, 0.f);
  const ProposalFeatureComputer computer(image, oaocc, regions, proposals, feature_options,
                                         limits.threads, std::move(colour));
  std::size_t done = 0;
  Clock::duration feature_time{};
  while (done < n) {
    if (limits.deadline != Clock::time_point::max() && Clock::now() > limits.deadline) break;
    const std::size_t end = std::min(n, done + kProposalsPerChunk);
    const Clock::time_point chunk_start = Clock::now();
    SplitRange(done, end, limits.threads,
               [&](std::size_t b, std::size_t e) { computer.ComputeRange(b, e, features); });
    feature_time += Clock::now() - chunk_start;
    SplitRange(done, end, limits.threads, [&](std::size_t b, std::size_t e) {
      // A row range is a view: the batched walk reads the rows in place.
      const std::vector<float> scores =
          bundle.ordr.PredictBatch(features.rowRange(static_cast<int>(b), static_cast<int>(e)));
      std::copy(scores.begin(), scores.end(), out.ordr.begin() + static_cast<long>(b));
    });
    done = end;
  }
  if (done < n) {
    out.truncated = true;
    out.dropped = n - done;
    proposals.boxes.resize(done);
    proposals.layer.resize(done);
    out.ordr.resize(done);
  }
  // Features and ORDR ran chunk by chunk, in turn: the time since the last mark splits into the
  // features' part and the rest, which regression gets below together with OBDR.
  if (timer)
    timer->MarkPart("features", std::chrono::duration<double, std::milli>(feature_time).count());
  if (timer && !timer->stopped().ok()) return out;  // cancelled: the caller returns the Status
  // OBDR only matters for the boxes that pass the fusion gate (top keep_ratio by ORDR, §6.5), so
  // only those are scored; the rest keep OBDR 0.
  const std::vector<int> gated = GatedByOrdr(out.ordr, bundle.params.fusion);
  std::vector<float> gated_obdr(gated.size(), 0.f);
  SplitRange(0, gated.size(), limits.threads, [&](std::size_t b, std::size_t e) {
    const std::vector<int> subset(gated.begin() + static_cast<long>(b),
                                  gated.begin() + static_cast<long>(e));
    const std::vector<float> scores = bundle.obdr.PredictBatch(features, subset);
    std::copy(scores.begin(), scores.end(), gated_obdr.begin() + static_cast<long>(b));
  });
  out.obdr.assign(out.ordr.size(), 0.f);
  for (std::size_t r = 0; r < gated.size(); ++r) out.obdr[gated[r]] = gated_obdr[r];
  if (timer) timer->Mark("regression");
  out.proposals = std::move(proposals);
  return out;
}

}  // namespace tod
