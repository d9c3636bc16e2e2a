#include "core/base/types.h"

#include <algorithm>

namespace tod {

// The far sides in 64 bits: a box read from a file may reach past INT_MAX (x + w), and the
// intersection's sides are then still ints (x1 - x0 <= a.w).
Box Intersect(const Box& a, const Box& b) {
  const long long x0 = std::max(a.x, b.x);
  const long long y0 = std::max(a.y, b.y);
  const long long x1 =
      std::min(static_cast<long long>(a.x) + a.w, static_cast<long long>(b.x) + b.w);
  const long long y1 =
      std::min(static_cast<long long>(a.y) + a.h, static_cast<long long>(b.y) + b.h);
  if (x1 <= x0 || y1 <= y0) return {};
  return {static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0),
          static_cast<int>(y1 - y0)};
}

Box ClipToImage(const Box& b, int width, int height) {
  return Intersect(b, Box{0, 0, width, height});
}

double BoxIoU(const Box& a, const Box& b) {
  const long long inter = Intersect(a, b).area();
  const long long uni = std::max(0LL, a.area()) + std::max(0LL, b.area()) - inter;
  return uni > 0 ? static_cast<double>(inter) / static_cast<double>(uni) : 0.0;
}

}  // namespace tod
