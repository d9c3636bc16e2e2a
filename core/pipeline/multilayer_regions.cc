#include "core/pipeline/multilayer_regions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "core/pipeline/json_integers.h"

namespace tod {
namespace {

struct Point2 {
  double a = 0, b = 0;
};

double Dist2(const Point2& p, const Point2& q) {
  return (p.a - q.a) * (p.a - q.a) + (p.b - q.b) * (p.b - q.b);
}

// One k-means++ run; returns SSE and fills the assignment.
double KMeansOnce(const std::vector<Point2>& pts, int k, int max_iterations, std::mt19937_64& rng,
                  std::vector<int>& assignment) {
  const int n = static_cast<int>(pts.size());
  std::vector<Point2> centres;
  std::uniform_int_distribution<int> pick(0, n - 1);
  centres.push_back(pts[pick(rng)]);
  std::vector<double> d2(n);
  while (static_cast<int>(centres.size()) < k) {
    double total = 0;
    for (int i = 0; i < n; ++i) {
      double best = std::numeric_limits<double>::max();
      for (const auto& c : centres) best = std::min(best, Dist2(pts[i], c));
      d2[i] = best;
      total += best;
    }
    if (total <= 0) {  // all points coincide with centres: duplicate one
      centres.push_back(pts[pick(rng)]);
      continue;
    }
    std::uniform_real_distribution<double> u(0, total);
    double r = u(rng);
    int chosen = n - 1;
    for (int i = 0; i < n; ++i) {
      r -= d2[i];
      if (r <= 0) {
        chosen = i;
        break;
      }
    }
    centres.push_back(pts[chosen]);
  }
  assignment.assign(n, 0);
  for (int iter = 0; iter < max_iterations; ++iter) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      int best = 0;
      for (int c = 1; c < k; ++c)
        if (Dist2(pts[i], centres[c]) < Dist2(pts[i], centres[best])) best = c;
      if (best != assignment[i]) changed = true;
      assignment[i] = best;
    }
    std::vector<Point2> sums(k);
    std::vector<int> counts(k, 0);
    for (int i = 0; i < n; ++i) {
      sums[assignment[i]].a += pts[i].a;
      sums[assignment[i]].b += pts[i].b;
      ++counts[assignment[i]];
    }
    for (int c = 0; c < k; ++c)
      if (counts[c] > 0) centres[c] = {sums[c].a / counts[c], sums[c].b / counts[c]};
    if (!changed && iter > 0) break;
  }
  double sse = 0;
  for (int i = 0; i < n; ++i) sse += Dist2(pts[i], centres[assignment[i]]);
  return sse;
}

Box Grow(const Box& b, double fraction, int width, int height) {
  const int dx = static_cast<int>(std::round(b.w * fraction));
  const int dy = static_cast<int>(std::round(b.h * fraction));
  return ClipToImage(Box{b.x - dx, b.y - dy, b.w + 2 * dx, b.h + 2 * dy}, width, height);
}

Box Union(const Box& a, const Box& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
  const int x1 = std::max(a.right(), b.right()), y1 = std::max(a.bottom(), b.bottom());
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace

int MultilayerRegions::LayerCount(int x, int y) const {
  int n = 0;
  for (const Box& r : layers)
    if (x >= r.x && x < r.right() && y >= r.y && y < r.bottom()) ++n;
  return n;
}

std::vector<int> MultilayerRegions::RangeLimits() const {
  std::vector<int> limits;
  for (const Box& r : layers) limits.push_back(r.bottom() - 1);
  if (!layers.empty()) limits.push_back(layers.back().y);
  // Enforce strictly decreasing limits so every range is well defined even for odd regions.
  for (std::size_t i = 1; i < limits.size(); ++i)
    limits[i] = std::min(limits[i], limits[i - 1] - 1);
  return limits;
}

MultilayerRegions MultilayerRegions::ScaledTo(int width, int height) const {
  if (width == image_width && height == image_height) return *this;
  MultilayerRegions out;
  out.image_width = width;
  out.image_height = height;
  const double sx = static_cast<double>(width) / std::max(1, image_width);
  const double sy = static_cast<double>(height) / std::max(1, image_height);
  for (const Box& r : layers) {
    const int x0 = static_cast<int>(std::floor(r.x * sx));
    const int y0 = static_cast<int>(std::floor(r.y * sy));
    const int x1 = static_cast<int>(std::ceil(r.right() * sx));
    const int y1 = static_cast<int>(std::ceil(r.bottom() * sy));
    out.layers.push_back(ClipToImage(Box{x0, y0, x1 - x0, y1 - y0}, width, height));
  }
  return out;
}

nlohmann::json MultilayerRegions::ToJson() const {
  nlohmann::json j;
  j["image_width"] = image_width;
  j["image_height"] = image_height;
  j["layers"] = nlohmann::json::array();
  for (const Box& r : layers) j["layers"].push_back({r.x, r.y, r.w, r.h});
  return j;
}

Result<MultilayerRegions> MultilayerRegions::FromJson(const nlohmann::json& j) {
  try {
    MultilayerRegions out;
    // Integers checked before they are converted (json_integers.h).
    Result<int> width = JsonToInt(j.at("image_width"), "regions: image_width");
    if (!width.ok()) return width.status();
    Result<int> height = JsonToInt(j.at("image_height"), "regions: image_height");
    if (!height.ok()) return height.status();
    out.image_width = *width;
    out.image_height = *height;
    for (const auto& r : j.at("layers")) {
      if (!r.is_array() || r.size() != 4 || !std::all_of(r.begin(), r.end(), IsJsonInt))
        return Status::InvalidArgument("region is not [x,y,w,h] of ints");
      out.layers.push_back({r[0].get<int>(), r[1].get<int>(), r[2].get<int>(), r[3].get<int>()});
    }
    if (out.image_width <= 0 || out.image_height <= 0 || out.layers.empty())
      return Status::InvalidArgument("regions need a positive image size and at least one layer");
    for (std::size_t k = 0; k < out.layers.size(); ++k) {
      const Box& r = out.layers[k];
      if (r.empty() || ClipToImage(r, out.image_width, out.image_height) != r)
        return Status::InvalidArgument("region R" + std::to_string(k + 1) +
                                       " is empty or outside the image");
    }
    return out;
  } catch (const nlohmann::json::exception& e) {
    return Status::InvalidArgument(std::string("regions: ") + e.what());
  }
}

Result<MultilayerRegions> DeriveMultilayerRegions(const std::vector<ObstacleFootprint>& obstacles,
                                                  int image_width, int image_height,
                                                  const RegionParams& params) {
  const int k = params.num_layers;
  if (k < 1) return Status::InvalidArgument("need at least one layer");
  if (static_cast<int>(obstacles.size()) < k)
    return Status::InvalidArgument("need at least " + std::to_string(k) +
                                   " training obstacles to derive " + std::to_string(k) +
                                   " layers, got " + std::to_string(obstacles.size()));
  // Features: bottom distance to the image's last row and pixel area, min-max normalised.
  std::vector<Point2> pts;
  for (const auto& o : obstacles)
    pts.push_back(
        {static_cast<double>(image_height - o.box.bottom()), static_cast<double>(o.pixels)});
  Point2 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  Point2 hi{std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  for (const auto& p : pts) {
    lo.a = std::min(lo.a, p.a), lo.b = std::min(lo.b, p.b);
    hi.a = std::max(hi.a, p.a), hi.b = std::max(hi.b, p.b);
  }
  for (auto& p : pts) {
    p.a = hi.a > lo.a ? (p.a - lo.a) / (hi.a - lo.a) : 0;
    p.b = hi.b > lo.b ? (p.b - lo.b) / (hi.b - lo.b) : 0;
  }
  std::mt19937_64 rng(params.seed);
  std::vector<int> best_assignment;
  double best_sse = std::numeric_limits<double>::max();
  for (int r = 0; r < std::max(1, params.restarts); ++r) {
    std::vector<int> assignment;
    const double sse = KMeansOnce(pts, k, params.max_iterations, rng, assignment);
    if (sse < best_sse) best_sse = sse, best_assignment = assignment;
  }
  // Order clusters near to far by mean bottom distance (ascending).
  std::vector<double> mean_bottom(k, 0);
  std::vector<int> counts(k, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    mean_bottom[best_assignment[i]] += pts[i].a;
    ++counts[best_assignment[i]];
  }
  std::vector<int> order(k);
  std::iota(order.begin(), order.end(), 0);
  for (int c = 0; c < k; ++c)
    mean_bottom[c] = counts[c] ? mean_bottom[c] / counts[c] : std::numeric_limits<double>::max();
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return mean_bottom[a] < mean_bottom[b]; });
  std::vector<int> rank_of_cluster(k);
  for (int r = 0; r < k; ++r) rank_of_cluster[order[r]] = r;

  MultilayerRegions out;
  out.image_width = image_width;
  out.image_height = image_height;
  Box previous;
  for (int layer = 0; layer < k; ++layer) {
    Box tight;
    for (std::size_t i = 0; i < obstacles.size(); ++i)
      if (rank_of_cluster[best_assignment[i]] >= layer) tight = Union(tight, obstacles[i].box);
    if (tight.empty()) tight = previous;  // an empty cluster: repeat the enclosing layer
    Box grown = Grow(tight, params.margin_fraction, image_width, image_height);
    if (layer > 0) grown = Intersect(grown, previous);  // keep R_{k+1} ⊆ R_k after the margin
    if (grown.empty()) grown = previous;
    out.layers.push_back(grown);
    previous = grown;
  }
  return out;
}

MultilayerRegions Laf2020Regions() {
  // §1.3, converted from 1-based inclusive [top_y, left_x, height, width] to 0-based half-open.
  MultilayerRegions out;
  out.image_width = 2048;
  out.image_height = 1024;
  out.layers = {
      {0, 225, 1893, 615}, {582, 308, 949, 404}, {841, 356, 433, 297}, {904, 373, 341, 141}};
  return out;
}

}  // namespace tod
