#include "core/data/pasted_obstacles.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>

namespace tod {
namespace {

constexpr int kPastedIdBase = 1000000;  // above every reader's instance ids

// 1 on the obstacle, falling linearly to 0 at `margin` pixels from it (Euclidean distance).
cv::Mat1f FeatheredAlpha(const cv::Mat1b& mask, int margin) {
  cv::Mat1b outside;
  cv::compare(mask, 0, outside, cv::CMP_EQ);
  cv::Mat1f distance;
  cv::distanceTransform(outside, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat1f alpha = 1.f - distance / static_cast<float>(margin);
  cv::max(alpha, 0.f, alpha);
  return alpha;
}

// Whether every pixel `alpha` would paste at `at` is free.
bool FitsAt(const ObstacleCutout& cutout, const Box& at, const cv::Mat1b& free) {
  for (int y = 0; y < at.h; ++y) {
    const float* a = cutout.alpha[y];
    const unsigned char* f = free[at.y + y] + at.x;
    for (int x = 0; x < at.w; ++x)
      if (a[x] > 0.f && f[x] == 0) return false;
  }
  return true;
}

// Mean absolute difference (grey levels, over channels) between the cut-out's road ring and the
// pixels of `image` it would cover at `at`: small where both are the same kind of surface.
// (Shifting the cut-out's colours to the target's road first, as under another frame's light,
// was measured and was worse: README "Real frames", point 22.)
double RingDifference(const ObstacleCutout& cutout, const Box& at, const cv::Mat3b& image) {
  double sum = 0.0;
  long long count = 0;
  for (int y = 0; y < at.h; ++y) {
    const float* a = cutout.alpha[y];
    const unsigned char* m = cutout.mask[y];
    const cv::Vec3b* from = cutout.patch[y];
    const cv::Vec3b* to = image[at.y + y] + at.x;
    for (int x = 0; x < at.w; ++x) {
      if (a[x] <= 0.f || m[x] != 0) continue;
      for (int c = 0; c < 3; ++c) sum += std::abs(static_cast<int>(from[x][c]) - to[x][c]);
      ++count;
    }
  }
  return count > 0 ? sum / (3.0 * count) : 0.0;
}

// Blends the cut-out into `sample` at `at`, marks its obstacle and takes its footprint out of
// `free`; returns the pasted instance.
ObstacleInstance PasteAt(const ObstacleCutout& cutout, const Box& at, Sample& sample,
                         cv::Mat1b& free) {
  for (int y = 0; y < at.h; ++y) {
    const float* a = cutout.alpha[y];
    const cv::Vec3b* from = cutout.patch[y];
    cv::Vec3b* to = sample.image[at.y + y] + at.x;
    unsigned char* f = free[at.y + y] + at.x;
    for (int x = 0; x < at.w; ++x) {
      if (a[x] <= 0.f) continue;
      for (int c = 0; c < 3; ++c)
        to[x][c] = cv::saturate_cast<unsigned char>(a[x] * from[x][c] + (1.f - a[x]) * to[x][c]);
      f[x] = 0;
    }
  }
  const cv::Rect tight = cv::boundingRect(cutout.mask);
  ObstacleInstance instance;
  instance.box = {at.x + tight.x, at.y + tight.y, tight.width, tight.height};
  instance.mask = cutout.mask(tight).clone();
  sample.obstacle(instance.box.rect()).setTo(255, instance.mask);
  sample.road(instance.box.rect()).setTo(0, instance.mask);
  return instance;
}

}  // namespace

ObstacleCutout CutOutObstacle(const Sample& sample, const ObstacleInstance& instance, int frame,
                              const PasteParams& params) {
  ObstacleCutout cutout;
  cutout.frame = frame;
  if (instance.box.empty() || instance.mask.size() != cv::Size(instance.box.w, instance.box.h))
    return cutout;
  const int margin = std::max(
      params.min_margin, static_cast<int>(std::lround(params.margin_fraction *
                                                      std::max(instance.box.w, instance.box.h))));
  const Box grown{instance.box.x - margin, instance.box.y - margin, instance.box.w + 2 * margin,
                  instance.box.h + 2 * margin};
  const Box box = ClipToImage(grown, sample.image.cols, sample.image.rows);
  const Box inside = Intersect(instance.box, box);
  if (box.empty() || inside.empty()) return cutout;
  cv::Mat1b mask = cv::Mat1b::zeros(box.h, box.w);
  const cv::Rect in_cut(inside.x - box.x, inside.y - box.y, inside.w, inside.h);
  const cv::Rect in_instance(inside.x - instance.box.x, inside.y - instance.box.y, inside.w,
                             inside.h);
  instance.mask(in_instance).copyTo(mask(in_cut));
  const cv::Mat1f alpha = FeatheredAlpha(mask, margin);
  // The ring must be free space: a ring over void or another obstacle would carry them along.
  for (int y = 0; y < box.h; ++y)
    for (int x = 0; x < box.w; ++x)
      if (mask(y, x) == 0 && alpha(y, x) > 0.f && sample.road(box.y + y, box.x + x) == 0)
        return cutout;
  cutout.box = box;
  cutout.patch = sample.image(box.rect()).clone();
  cutout.mask = mask;
  cutout.alpha = alpha;
  return cutout;
}

Sample PasteObstacles(const Sample& target, const std::vector<const ObstacleCutout*>& donors,
                      std::uint64_t seed, const PasteParams& params) {
  Sample out = target;
  out.name = target.name + "+pasted";
  out.image = target.image.clone();
  out.road = target.road.clone();
  out.obstacle =
      target.obstacle.empty() ? cv::Mat1b::zeros(target.image.size()) : target.obstacle.clone();
  out.ignore =
      target.ignore.empty() ? cv::Mat1b::zeros(target.image.size()) : target.ignore.clone();
  cv::Mat1b free = out.road.clone();  // where a cut-out may still go
  std::mt19937_64 rng(seed);
  std::vector<int> order(donors.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  const int width = out.image.cols;
  const int max_shift = static_cast<int>(params.max_shift_fraction * width);
  std::uniform_int_distribution<int> shift(-max_shift, max_shift);
  int pasted = 0;
  for (const int d : order) {
    if (pasted >= params.obstacles_per_frame) break;
    const ObstacleCutout& cutout = *donors[d];
    if (cutout.patch.empty() || cutout.box.bottom() > out.image.rows) continue;
    // Of the shifts that fit, the one whose surface matches the cut-out's own road best: free
    // space includes cars, walls and verges where a set has no road label.
    Box best;
    double best_difference = params.max_ring_difference;
    for (int t = 0; t < params.tries; ++t) {
      const Box at{cutout.box.x + shift(rng), cutout.box.y, cutout.box.w, cutout.box.h};
      if (at.x < 0 || at.right() > width || !FitsAt(cutout, at, free)) continue;
      const double difference = RingDifference(cutout, at, out.image);
      if (difference <= best_difference) best = at, best_difference = difference;
    }
    if (best.empty()) continue;
    out.instances.push_back(PasteAt(cutout, best, out, free));
    out.instances.back().id = kPastedIdBase + pasted;
    ++pasted;
  }
  return out;
}

void VoidOwnObstacles(Sample& pasted, std::size_t own) {
  own = std::min(own, pasted.instances.size());
  for (std::size_t k = 0; k < own; ++k) {
    const ObstacleInstance& inst = pasted.instances[k];
    const Box b = ClipToImage(inst.box, pasted.image.cols, pasted.image.rows);
    if (b.empty() || inst.mask.size() != cv::Size(inst.box.w, inst.box.h)) continue;
    const cv::Mat1b member = inst.mask(cv::Rect(b.x - inst.box.x, b.y - inst.box.y, b.w, b.h));
    pasted.ignore(b.rect()).setTo(255, member);
    pasted.obstacle(b.rect()).setTo(0, member);
  }
  pasted.instances.erase(pasted.instances.begin(), pasted.instances.begin() + own);
}

}  // namespace tod
