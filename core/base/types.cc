#include "core/base/types.h"

#include <algorithm>

namespace tod {

Box Intersect(const Box& a, const Box& b) {
  const int x0 = std::max(a.x, b.x);
  const int y0 = std::max(a.y, b.y);
  const int x1 = std::min(a.right(), b.right());
  const int y1 = std::min(a.bottom(), b.bottom());
  if (x1 <= x0 || y1 <= y0) return {};
  return {x0, y0, x1 - x0, y1 - y0};
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
