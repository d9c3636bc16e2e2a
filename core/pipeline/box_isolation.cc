#include "core/pipeline/box_isolation.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tod {
namespace {

struct Centre {
  float x = 0.f, y = 0.f;
};

Centre CentreOf(const Box& b) { return {b.x + 0.5f * b.w, b.y + 0.5f * b.h}; }

// Centres of the `count` best boxes by score (stable: earlier boxes first on ties).
std::vector<Centre> ContextCentres(const std::vector<ScoredBox>& frame_boxes, int count) {
  std::vector<int> order(frame_boxes.size());
  std::iota(order.begin(), order.end(), 0);
  const std::size_t n = std::min<std::size_t>(order.size(), static_cast<std::size_t>(count));
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(),
                    [&](int a, int b) {
                      return frame_boxes[a].score > frame_boxes[b].score ||
                             (frame_boxes[a].score == frame_boxes[b].score && a < b);
                    });
  std::vector<Centre> centres;
  centres.reserve(n);
  for (std::size_t i = 0; i < n; ++i) centres.push_back(CentreOf(frame_boxes[order[i]].box));
  return centres;
}

}  // namespace

std::vector<float> IsolationWeights(const std::vector<ScoredBox>& boxes,
                                    const std::vector<ScoredBox>& frame_boxes,
                                    const BoxIsolationParams& params) {
  std::vector<float> weights(boxes.size(), 1.f);
  if (params.exponent == 0.f) return weights;
  const std::vector<Centre> context = ContextCentres(frame_boxes, params.context_boxes);
  const float reach = 0.5f * params.surround;  // half-extent of the surround, in box sizes
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i].box;
    const Centre c = CentreOf(b);
    int inside = 0, surround = 0;
    for (const Centre& o : context) {
      const float dx = std::abs(o.x - c.x), dy = std::abs(o.y - c.y);
      if (dx > reach * b.w || dy > reach * b.h) continue;
      ++surround;
      inside += dx <= 0.5f * b.w && dy <= 0.5f * b.h;
    }
    // A box with no context centre inside still holds its own: one of (surround + 1).
    if (inside == 0) ++inside, ++surround;
    const double isolation = static_cast<double>(inside) / surround;
    weights[i] = static_cast<float>(std::pow(isolation, params.exponent));
  }
  return weights;
}

}  // namespace tod
