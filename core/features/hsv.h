// Colour conversion and histogram bins of the colour features (ALGORITHM.md §5, features 15-20).
// BgrToHsv / HueBin / SatValBin are the reference definitions; ClassifyPixel is the fast form used
// when building the per-pixel tables and gives the same bins.
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

namespace tod {

// Histogram layout of the colour-contrast features (ALGORITHM.md §5, features 18-20).
inline constexpr int kHueBins = 16;     // 17 non-uniform edges, last bin merged into the first
inline constexpr int kSatValBins = 16;  // uniform, width 1/16; 1.0 falls in the last bin
inline constexpr int kColourHistBins = kHueBins + 2 * kSatValBins;  // 48: H, then S, then V

// MATLAB rgb2hsv of one 8-bit BGR pixel: H, S, V all in [0, 1], H linear (not circular).
cv::Vec3f BgrToHsv(const cv::Vec3b& bgr);
// Hue histogram bin (0..15) of a hue given in degrees [0, 360).
int HueBin(double hue_degrees);
// Saturation / value histogram bin (0..15) of a value in [0, 1].
int SatValBin(float value);

namespace hsv_internal {
constexpr std::array<double, 256> MakeInverseLevels(int factor) {
  std::array<double, 256> inverse{};
  for (int level = 1; level < 256; ++level) inverse[level] = 1.0 / (factor * level);
  return inverse;
}
constexpr std::array<float, 256> MakeLevelValues() {
  std::array<float, 256> value{};
  for (int level = 0; level < 256; ++level) value[level] = static_cast<float>(level / 255.0);
  return value;
}
inline constexpr std::array<double, 256> kInverseLevel = MakeInverseLevels(1);     // 1 / l
inline constexpr std::array<double, 256> kInverseSixLevel = MakeInverseLevels(6);  // 1 / (6 l)
inline constexpr std::array<float, 256> kLevelValue = MakeLevelValues();           // l / 255
}  // namespace hsv_internal

// H, S, V of a pixel from max_level = max(b, g, r), delta = max - min and hue_units = the hue in
// units of 60 degrees times delta (an integer in [0, 6 delta), see ClassifyPixel). Within one
// float ulp of BgrToHsv; used wherever the features need the float values, so that they are the
// same numbers everywhere.
inline cv::Vec3f HsvFromLevels(int max_level, int delta, int hue_units) {
  return {static_cast<float>(hue_units * hsv_internal::kInverseSixLevel[delta]),
          static_cast<float>(delta * hsv_internal::kInverseLevel[max_level]),
          hsv_internal::kLevelValue[max_level]};
}

// Histogram bins and integer hue / saturation description of one 8-bit BGR pixel, without
// divisions in the common case. The bins equal HueBin(BgrToHsv(p)[0] * 360),
// SatValBin(BgrToHsv(p)[1]) and SatValBin(BgrToHsv(p)[2]) for every colour (tested
// exhaustively), including the hues that lie exactly on a bin edge, where the reference's float
// rounding puts them in the lower bin (e.g. 55 degrees -> bin 3; MATLAB's double rgb2hsv rounds
// the same way). HsvFromLevels(max_level, delta, hue_units) gives the float H, S, V.
struct PixelColour {
  std::uint8_t hue_bin = 0, sat_bin = 0, val_bin = 0;
  std::uint8_t max_level = 0, delta = 0;
  std::uint16_t hue_units = 0;
};
PixelColour ClassifyPixel(std::uint8_t b, std::uint8_t g, std::uint8_t r);

}  // namespace tod
