#include "core/synth/synth_textures.h"

#include <algorithm>
#include <cmath>

namespace tod::synth {
namespace {

float Smooth(float t) { return t * t * (3.0f - 2.0f * t); }

// Weight of a texture feature of `cell_m` metres when one pixel covers `mpp` metres: full when
// the feature spans >= 3 pixels, gone below 1.5 pixels.
float Visibility(double cell_m, double mpp) {
  return static_cast<float>(std::clamp((cell_m / mpp - 1.5) / 1.5, 0.0, 1.0));
}

float HashUnit(std::uint64_t seed, std::int64_t a, std::int64_t b) {
  const std::uint64_t h = MixSeed(seed ^ MixSeed(static_cast<std::uint64_t>(a) * 0x9E3779B1ULL +
                                                 static_cast<std::uint64_t>(b)));
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f) * 2.0f - 1.0f;
}

}  // namespace

ValueNoise::ValueNoise(Rng& rng) : table_(kPeriod * kPeriod) {
  for (float& v : table_) v = static_cast<float>(rng.Uniform(-1.0, 1.0));
}

float ValueNoise::At(double x, double z) const {
  int ix = static_cast<int>(x), iz = static_cast<int>(z);
  if (x < ix) --ix;  // floor without a libm call
  if (z < iz) --iz;
  const float tx = Smooth(static_cast<float>(x - ix)), tz = Smooth(static_cast<float>(z - iz));
  ix &= kPeriod - 1;
  iz &= kPeriod - 1;
  const int ix1 = (ix + 1) & (kPeriod - 1), iz1 = (iz + 1) & (kPeriod - 1);
  const float a = table_[iz * kPeriod + ix], b = table_[iz * kPeriod + ix1];
  const float c = table_[iz1 * kPeriod + ix], d = table_[iz1 * kPeriod + ix1];
  const float top = a + (b - a) * tx, bottom = c + (d - c) * tx;
  return top + (bottom - top) * tz;
}

ValueNoise::Octaves ValueNoise::OctavesFor(double coarsest_m, int octaves, float persistence,
                                           double metres_per_pixel) {
  Octaves out;
  float amplitude = 1.0f, total = 0.0f;
  double cell = coarsest_m;
  for (int o = 0; o < std::min(octaves, Octaves::kMax); ++o) {
    total += amplitude;
    const float w = Visibility(cell, metres_per_pixel);
    if (w > 0.0f) {
      out.inv_cell[out.count] = 1.0 / cell;
      out.weight[out.count] = w * amplitude;
      ++out.count;
    }
    amplitude *= persistence;
    cell *= 0.5;
  }
  for (int i = 0; i < out.count; ++i) out.weight[i] /= total;
  return out;
}

float ValueNoise::Fractal(double x, double z, const Octaves& octaves) const {
  float sum = 0.0f;
  for (int o = 0; o < octaves.count; ++o) {
    // Each octave is shifted so the lattices do not line up.
    sum += octaves.weight[o] *
           At(x * octaves.inv_cell[o] + 37.1 * o, z * octaves.inv_cell[o] + 91.7 * o);
  }
  return sum;
}

namespace {

// Everything about a material that depends only on the image row (distance).
struct MaterialRow {
  const GroundMaterial* m = nullptr;
  ValueNoise::Octaves blotch, grain;
  float tile_visible = 0.0f;
  float joint_coverage = 0.0f;
  double joint_half_m = 0.0;
};

MaterialRow PrepareRow(const GroundMaterial& m, double mpp) {
  constexpr double kJointM = 0.012;
  MaterialRow r;
  r.m = &m;
  r.blotch = ValueNoise::OctavesFor(m.blotch_cell_m, 3, 0.5f, mpp);
  r.grain = ValueNoise::OctavesFor(m.grain_cell_m, 3, 0.7f, mpp);
  if (m.tiles) {
    r.tile_visible = Visibility(std::min(m.tile_across_m, m.tile_along_m) * 0.5, mpp);
    // A 1.2 cm joint darkens the pixels within half a joint (or half a pixel) of a tile edge,
    // scaled by the fraction of the pixel it covers.
    r.joint_coverage = static_cast<float>(std::min(1.0, kJointM / mpp));
    r.joint_half_m = 0.5 * std::max(kJointM, mpp);
  }
  return r;
}

cv::Vec3f ShadePixel(const MaterialRow& r, const ValueNoise& noise, std::uint64_t tile_seed,
                     double x, double z, double road_centre_x) {
  const GroundMaterial& m = *r.m;
  float factor = 1.0f + m.blotch_amp * noise.Fractal(x, z, r.blotch) +
                 m.grain_amp * noise.Fractal(x + 500.0, z, r.grain);
  if (m.tiles && r.tile_visible > 0.0f) {
    const double v = z / m.tile_along_m;
    const double row = std::floor(v);
    const double u = x / m.tile_across_m + (static_cast<long long>(row) % 2 != 0 ? 0.5 : 0.0);
    const double col = std::floor(u);
    factor += r.tile_visible * m.tile_jitter *
              HashUnit(tile_seed, static_cast<std::int64_t>(col), static_cast<std::int64_t>(row));
    const double du = std::min(u - col, col + 1.0 - u) * m.tile_across_m;
    const double dv = std::min(v - row, row + 1.0 - v) * m.tile_along_m;
    if (std::min(du, dv) < r.joint_half_m)
      factor -= r.tile_visible * m.joint_darkness * r.joint_coverage;
  }
  for (double track : m.wheel_tracks_m) {
    // Smooth bump of half-width ~0.5 m (polynomial: no exp per pixel).
    const double d = (x - road_centre_x - track) * 2.0;
    if (d > -1.0 && d < 1.0) {
      const double b = 1.0 - d * d;
      factor -= m.wheel_track_darkness * static_cast<float>(b * b);
    }
  }
  return m.base * std::max(0.05f, factor);
}

}  // namespace

void ShadeGround(Canvas& canvas, const PinholeCamera& camera, const GroundMaterials& materials,
                 const ValueNoise& noise, std::uint64_t tile_seed,
                 const std::function<double(double)>& road_centre_at) {
  const int first_row = std::max(0, static_cast<int>(std::floor(camera.horizon_row)) + 1);
  for (int y = first_row; y < canvas.colour.rows; ++y) {
    const double row = y + 0.5;
    if (row <= camera.horizon_row + 0.25) continue;
    const double z = camera.GroundDistanceAtRow(row);
    const double mpp = camera.MetresPerPixel(z);
    const double centre = road_centre_at(z);
    const MaterialRow rows[4] = {
        PrepareRow(materials.road, mpp), PrepareRow(materials.sidewalk, mpp),
        PrepareRow(materials.verge, mpp), PrepareRow(materials.far_ground, mpp)};
    const uchar* surface = canvas.surface.ptr<uchar>(y);
    cv::Vec3f* colour = canvas.colour.ptr<cv::Vec3f>(y);
    const double x0 = (0.5 - camera.center_x) * mpp;  // world X of column 0; + mpp per column
    for (int x = 0; x < canvas.colour.cols; ++x) {
      int which;
      switch (static_cast<Surface>(surface[x])) {
        case Surface::kRoad:
          which = 0;
          break;
        case Surface::kSidewalk:
          which = 1;
          break;
        case Surface::kVerge:
          which = 2;
          break;
        case Surface::kFarGround:
          which = 3;
          break;
        default:
          continue;
      }
      colour[x] = ShadePixel(rows[which], noise, tile_seed, x0 + x * mpp, z, centre);
    }
  }
}

}  // namespace tod::synth
