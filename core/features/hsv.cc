#include "core/features/hsv.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace tod {
namespace {

// Hue bin edges in degrees (ALGORITHM.md §5). Bins are half-open [e_i, e_{i+1}); the 17th bin
// [345, 361) is red again and is merged into bin 0.
constexpr std::array<int, 18> kHueEdges = {0,   15,  25,  45,  55,  80,  108, 140, 165,
                                           190, 220, 255, 275, 290, 316, 330, 345, 361};

// Lookup tables of ClassifyPixel, all exact functions of an 8-bit level.
struct ClassifyTables {
  std::array<std::uint8_t, 256> value_bin{};  // SatValBin(level / 255) = min(15, 16 l / 255)
  std::array<std::uint8_t, 360> hue_bin{};    // bin of each whole degree (edges are integers)
  std::array<bool, 360> is_hue_edge{};
};

constexpr ClassifyTables MakeClassifyTables() {
  ClassifyTables t;
  for (int level = 0; level < 256; ++level) {
    t.value_bin[level] = static_cast<std::uint8_t>(std::min(kSatValBins - 1, 16 * level / 255));
  }
  for (int degree = 0; degree < 360; ++degree) {
    int bin = 0;
    for (int i = 0; i < kHueBins + 1; ++i) {
      if (degree >= kHueEdges[i]) bin = i;
    }
    t.hue_bin[degree] = static_cast<std::uint8_t>(bin == kHueBins ? 0 : bin);
  }
  for (int i = 0; i < kHueBins + 1; ++i) t.is_hue_edge[kHueEdges[i]] = true;
  return t;
}

constexpr ClassifyTables kTables = MakeClassifyTables();

// floor(x) of a quotient of 8-bit integers computed as a product with a rounded reciprocal: a
// non-integer quotient is at least 1/255 away from the next integer, an integer one is off by
// far less than 1e-9, so adding 1e-9 before truncating gives the exact floor.
constexpr double kQuotientSlack = 1e-9;

}  // namespace

cv::Vec3f BgrToHsv(const cv::Vec3b& bgr) {
  const double b = bgr[0] / 255.0, g = bgr[1] / 255.0, r = bgr[2] / 255.0;
  const double v = std::max({r, g, b});
  const double delta = v - std::min({r, g, b});
  if (delta <= 0.0) return {0.f, 0.f, static_cast<float>(v)};  // grey: hue and saturation 0
  double sextant;                                              // hue in units of 60 degrees, [0, 6)
  if (v == r) {
    sextant = (g - b) / delta;
    if (sextant < 0.0) sextant += 6.0;
  } else if (v == g) {
    sextant = 2.0 + (b - r) / delta;
  } else {
    sextant = 4.0 + (r - g) / delta;
  }
  return {static_cast<float>(sextant / 6.0), static_cast<float>(delta / v), static_cast<float>(v)};
}

int HueBin(double hue_degrees) {
  const auto upper = std::upper_bound(kHueEdges.begin(), kHueEdges.end(), hue_degrees);
  const int bin = static_cast<int>(upper - kHueEdges.begin()) - 1;
  if (bin < 0) return 0;          // below 0 degrees: cannot happen for rgb2hsv
  if (bin >= kHueBins) return 0;  // [345, 361) and beyond: red wrap-around
  return bin;
}

int SatValBin(float value) {
  // Width 1/16 is a power of two, so value * 16 is exact; 1.0 lands in bin 15 (last edge 1.1).
  const int bin = static_cast<int>(std::floor(value * static_cast<float>(kSatValBins)));
  return std::clamp(bin, 0, kSatValBins - 1);
}

PixelColour ClassifyPixel(std::uint8_t b, std::uint8_t g, std::uint8_t r) {
  const int max_level = std::max({b, g, r});
  const int delta = max_level - std::min({b, g, r});
  PixelColour out;
  out.max_level = static_cast<std::uint8_t>(max_level);
  out.delta = static_cast<std::uint8_t>(delta);
  out.val_bin = kTables.value_bin[max_level];
  if (delta == 0) return out;  // grey (or black): H = S = 0, bins 0
  // Same case order as rgb2hsv: red wins ties, then green.
  int hue_units;
  if (max_level == r) {
    hue_units = g - b;
    if (hue_units < 0) hue_units += 6 * delta;
  } else if (max_level == g) {
    hue_units = 2 * delta + b - r;
  } else {
    hue_units = 4 * delta + r - g;
  }
  out.hue_units = static_cast<std::uint16_t>(hue_units);
  const double saturation16 =
      16.0 * delta * hsv_internal::kInverseLevel[max_level] + kQuotientSlack;
  out.sat_bin =
      static_cast<std::uint8_t>(std::min(kSatValBins - 1, static_cast<int>(saturation16)));
  const double degrees = 60.0 * hue_units * hsv_internal::kInverseLevel[delta] + kQuotientSlack;
  const int whole_degrees = static_cast<int>(degrees);
  if (kTables.is_hue_edge[whole_degrees] && degrees - whole_degrees < 2 * kQuotientSlack) {
    // The hue is exactly a bin edge: the reference's rounding decides (see hsv.h).
    out.hue_bin = static_cast<std::uint8_t>(HueBin(BgrToHsv({b, g, r})[0] * 360.0));
  } else {
    out.hue_bin = kTables.hue_bin[whole_degrees];
  }
  return out;
}

}  // namespace tod
