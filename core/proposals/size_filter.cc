#include "core/proposals/size_filter.h"

#include <algorithm>
#include <limits>

namespace tod {
namespace {

double CenterY(const Box& b) { return b.y + 0.5 * b.h; }

bool InClosed(double v, double lo, double hi) { return v >= lo && v <= hi; }

// Slack of band i (1-based) in pixels (§4.3).
double Slack(int band_number) { return 20.0 * band_number; }

}  // namespace

bool SizeFilter::Keep(const Box& box) const {
  if (!enabled) return true;
  const double cy = CenterY(box);
  const double area = static_cast<double>(box.area());
  for (const SizeBand& band : bands) {
    if (!(cy > band.center_y_min && cy < band.center_y_max)) continue;  // open interval
    if (InClosed(box.h, band.h_min, band.h_max) && InClosed(box.w, band.w_min, band.w_max) &&
        InClosed(area, band.area_min, band.area_max)) {
      return true;
    }
  }
  return false;
}

std::vector<ScoredBox> SizeFilter::Apply(const std::vector<ScoredBox>& boxes) const {
  std::vector<ScoredBox> kept;
  kept.reserve(boxes.size());
  for (const ScoredBox& b : boxes) {
    if (Keep(b.box)) kept.push_back(b);
  }
  return kept;
}

SizeFilter SizeFilter::Derive(const std::vector<Box>& training_obstacle_boxes, int num_bands) {
  SizeFilter filter;
  std::vector<Box> boxes;
  for (const Box& b : training_obstacle_boxes) {
    if (!b.empty()) boxes.push_back(b);
  }
  if (boxes.empty() || num_bands < 1) {
    filter.enabled = false;  // nothing to derive from: a filter that keeps everything
    return filter;
  }
  double y_min = std::numeric_limits<double>::max(), y_max = std::numeric_limits<double>::lowest();
  for (const Box& b : boxes) {
    y_min = std::min(y_min, CenterY(b));
    y_max = std::max(y_max, CenterY(b));
  }
  const double band_height = (y_max - y_min) / num_bands;
  filter.bands.resize(num_bands);
  for (int i = 0; i < num_bands; ++i) {
    SizeBand& band = filter.bands[i];
    // As in the shipped LAF table: band i is (y_min + i d - 1, y_min + (i + 1) d), so the bands
    // overlap by one pixel; the last band is closed off one pixel past y_max (our choice) so that
    // the lowest training obstacle passes its own filter.
    band.center_y_min = y_min + i * band_height - 1.0;
    band.center_y_max = i + 1 == num_bands ? y_max + 1.0 : y_min + (i + 1) * band_height;
    band.h_min = band.w_min = band.area_min = std::numeric_limits<double>::max();
    band.h_max = band.w_max = band.area_max = std::numeric_limits<double>::lowest();
  }
  std::vector<int> members(num_bands, 0);
  for (const Box& b : boxes) {
    int i = band_height > 0 ? static_cast<int>((CenterY(b) - y_min) / band_height) : 0;
    i = std::clamp(i, 0, num_bands - 1);
    SizeBand& band = filter.bands[i];
    ++members[i];
    band.h_min = std::min<double>(band.h_min, b.h);
    band.h_max = std::max<double>(band.h_max, b.h);
    band.w_min = std::min<double>(band.w_min, b.w);
    band.w_max = std::max<double>(band.w_max, b.w);
    band.area_min = std::min<double>(band.area_min, static_cast<double>(b.area()));
    band.area_max = std::max<double>(band.area_max, static_cast<double>(b.area()));
  }
  for (int i = 0; i < num_bands; ++i) {
    SizeBand& band = filter.bands[i];
    if (members[i] == 0) {  // an empty band keeps nothing
      band.h_min = band.w_min = band.area_min = 1.0;
      band.h_max = band.w_max = band.area_max = 0.0;
      continue;
    }
    // Slack 20 i on both ends of h and w and on the upper end of the area; the shipped table
    // has no slack on the lower area bound (§4.3).
    const double slack = Slack(i + 1);
    band.h_min -= slack;
    band.h_max += slack;
    band.w_min -= slack;
    band.w_max += slack;
    band.area_max += slack;
  }
  return filter;
}

SizeFilter SizeFilter::Laf2020() {
  // §4.3 table (MATLAB, 1-based rows). Centre rows convert to our 0-based coordinates by
  // subtracting 1; h, w and area are pixel counts in both conventions and stay as they are.
  struct Row {
    double y0, y1, h0, h1, w0, w1, a0, a1;
  };
  constexpr Row kTable[] = {
      {244.0, 440.0 + 1.0 / 3.0, 1, 97, 6, 166, 10, 9405},
      {439.0 + 1.0 / 3.0, 635.0 + 2.0 / 3.0, 1, 232, 4, 677, 10, 79560},
      {634.0 + 2.0 / 3.0, 831.0, 22, 293, 52, 938, 1820, 164150},
  };
  SizeFilter filter;
  int band_number = 1;
  for (const Row& row : kTable) {
    const double slack = Slack(band_number++);
    filter.bands.push_back(SizeBand{row.y0 - 1.0, row.y1 - 1.0, row.h0 - slack, row.h1 + slack,
                                    row.w0 - slack, row.w1 + slack, row.a0, row.a1 + slack});
  }
  return filter;
}

nlohmann::json SizeFilter::ToJson() const {
  nlohmann::json j;
  j["enabled"] = enabled;
  j["bands"] = nlohmann::json::array();
  for (const SizeBand& b : bands) {
    j["bands"].push_back({{"center_y_min", b.center_y_min},
                          {"center_y_max", b.center_y_max},
                          {"h_min", b.h_min},
                          {"h_max", b.h_max},
                          {"w_min", b.w_min},
                          {"w_max", b.w_max},
                          {"area_min", b.area_min},
                          {"area_max", b.area_max}});
  }
  return j;
}

SizeFilter SizeFilter::FromJson(const nlohmann::json& j) {
  SizeFilter filter;
  filter.enabled = j.at("enabled").get<bool>();
  // get<vector> throws type_error unless "bands" is an array.
  for (const nlohmann::json& b : j.at("bands").get<std::vector<nlohmann::json>>()) {
    SizeBand band;
    band.center_y_min = b.at("center_y_min").get<double>();
    band.center_y_max = b.at("center_y_max").get<double>();
    band.h_min = b.at("h_min").get<double>();
    band.h_max = b.at("h_max").get<double>();
    band.w_min = b.at("w_min").get<double>();
    band.w_max = b.at("w_max").get<double>();
    band.area_min = b.at("area_min").get<double>();
    band.area_max = b.at("area_max").get<double>();
    filter.bands.push_back(band);
  }
  return filter;
}

}  // namespace tod
