// The frame being drawn by the synthetic generator: colour plus the two LAF label images, kept in
// step by every paint call so the ground truth is exactly what was drawn (painter's order: later
// paint occludes earlier paint, in the image and in the labels alike).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/synth/synth_rng.h"

namespace tod::synth {

// What kind of thing a pixel shows; shadows and decals only land on the ground kinds.
enum class Surface : std::uint8_t {
  kSky = 0,
  kFarGround,  // ground beyond the road's end or beside the verge
  kVerge,      // grass / gravel / parking area beside the road
  kSidewalk,
  kCurb,  // the curb's vertical face
  kRoad,
  kStanding,  // anything standing on the ground: buildings, cars, obstacles
};

inline bool IsGround(Surface s) {
  return s == Surface::kFarGround || s == Surface::kVerge || s == Surface::kSidewalk ||
         s == Surface::kRoad;
}

// LAF encoding (ALGORITHM.md §9.1): instanceIds 0 background, 1000 free space,
// class * 1000 + k obstacle k; labelIds 0 background, 1 free space, 2..43 obstacle class.
constexpr std::uint16_t kRoadInstanceId = 1000;
constexpr std::uint8_t kRoadLabelId = 1;

struct Labels {
  std::uint16_t instance_id = 0;
  std::uint8_t label_id = 0;
};

struct Canvas {
  explicit Canvas(cv::Size size);
  cv::Size size() const { return colour.size(); }

  cv::Mat3f colour;  // BGR, 0..255 scale, before camera effects
  cv::Mat1w instance_ids;
  cv::Mat1b label_ids;
  cv::Mat1b surface;  // Surface per pixel
  cv::Mat1f detail;   // image-space fractal noise in about [-1, 1] for textures
};

// A rasterised shape: a binary mask over `roi` (already clipped to the frame).
struct Region {
  cv::Rect roi;
  cv::Mat1b mask;
  bool empty() const { return roi.area() == 0; }
};

// Fills the polygons (image coordinates, sub-pixel) into a mask; points far outside the frame are
// fine. Polygons of one call are unioned.
Region RasterisePolygons(const std::vector<std::vector<cv::Point2d>>& polygons, cv::Size frame);
Region RasteriseEllipse(cv::Point2d centre, cv::Size2d semi_axes, double angle_deg, cv::Size frame);
// Keeps only the region pixels whose surface is road (decals, markings).
void RestrictToSurface(const Canvas& canvas, Region& region, Surface keep);

// Sets region pixels to colour * (1 + texture_amp * detail) and, if given, writes labels and the
// surface kind.
void Paint(Canvas& canvas, const Region& region, const cv::Vec3f& colour, float texture_amp,
           std::optional<Labels> labels, std::optional<Surface> surface);
// Blends colour over region pixels with opacity alpha (labels untouched: paint on the road is
// still road).
void Blend(Canvas& canvas, const Region& region, const cv::Vec3f& colour, float alpha,
           float texture_amp);
// Multiplies the ground pixels under a softened region by (1 - strength): shadows.
void Darken(Canvas& canvas, const Region& region, float strength, double soft_px);

// Smooth fractal noise of the given size, about zero mean and in [-1, 1]; `coarsest_px` is the
// feature size of the first octave.
cv::Mat1f FractalNoise(cv::Size size, double coarsest_px, int octaves, Rng& rng);

}  // namespace tod::synth
