#include "core/pipeline/detection_output.h"

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/base/atomic_file.h"

namespace tod {

nlohmann::json DetectionToJson(const Detection& d, const std::string& image_name) {
  nlohmann::json j;
  j["image"] = image_name;
  j["width"] = d.width;
  j["height"] = d.height;
  j["proposals"] = nlohmann::json::array();
  for (const Proposal& p : d.proposals)
    j["proposals"].push_back({{"x", p.box.x},
                              {"y", p.box.y},
                              {"w", p.box.w},
                              {"h", p.box.h},
                              {"score", p.fused},
                              {"ordr", p.ordr},
                              {"obdr", p.obdr}});
  j["obstacles"] = nlohmann::json::array();
  for (const DetectedObstacle& o : d.obstacles)
    j["obstacles"].push_back({{"x", o.box.x},
                              {"y", o.box.y},
                              {"w", o.box.w},
                              {"h", o.box.h},
                              {"area", o.area},
                              {"peak", o.peak_probability},
                              {"score", o.score},
                              {"evidence", o.evidence},
                              {"mean", o.mean_probability}});
  nlohmann::json timing = nlohmann::json::object();
  double total = 0;
  for (const auto& [stage, ms] : d.timings) {
    timing[stage] = ms;
    total += ms;
  }
  timing["total"] = total;
  j["timing_ms"] = timing;
  j["map_kind"] = MapKindName(d.map_kind);
  j["degraded"] = d.degraded();
  j["degraded_stages"] = d.degraded_stages;
  j["geometry"] = GeometryToJson(d);
  return j;
}

nlohmann::json GeometryToJson(const Detection& d) {
  const HorizonUse& h = d.horizon;
  const auto row = [](const std::optional<double>& r) {
    return r ? nlohmann::json(*r) : nlohmann::json(nullptr);
  };
  const Box& r = d.road_region;
  nlohmann::json j = {{"source", HorizonSourceName(h.source)},
                      {"horizon_row", row(h.row)},
                      {"bundle_horizon_row", row(h.bundle_row)},
                      {"frame_horizon_row", row(h.frame_estimate)},
                      {"camera_frames", h.camera_frames},
                      {"shift_rows", h.shift},
                      {"road_region", {{"x", r.x}, {"y", r.y}, {"w", r.w}, {"h", r.h}}}};
  if (!h.fallback.empty()) j["fallback"] = h.fallback;
  return j;
}

cv::Mat1b ProbabilityTo8Bit(const cv::Mat1f& probability) {
  cv::Mat1b out;
  probability.convertTo(out, CV_8U, 255.0);  // saturating, rounds to nearest
  return out;
}

cv::Mat3b DrawOverlay(const cv::Mat3b& bgr, const Detection& d, int top_proposals) {
  cv::Mat3b out = bgr.clone();
  if (!d.probability.empty() && d.probability.size() == bgr.size()) {
    cv::Mat3b heat(bgr.size(), cv::Vec3b(0, 0, 255));
    for (int y = 0; y < out.rows; ++y)
      for (int x = 0; x < out.cols; ++x) {
        const float a = 0.6f * d.probability(y, x);
        if (a <= 0.f) continue;
        cv::Vec3b& p = out(y, x);
        for (int c = 0; c < 3; ++c)
          p[c] = cv::saturate_cast<uchar>((1.f - a) * p[c] + a * heat(y, x)[c]);
      }
  }
  const int n = std::min<int>(top_proposals, static_cast<int>(d.proposals.size()));
  for (int i = n - 1; i >= 0; --i) cv::rectangle(out, d.proposals[i].box.rect(), {255, 255, 0}, 1);
  const double scale = std::max(0.4, bgr.cols / 2048.0);
  for (const DetectedObstacle& o : d.obstacles) {
    cv::rectangle(out, o.box.rect(), {0, 255, 255}, std::max(1, static_cast<int>(2 * scale)));
    char label[32];
    std::snprintf(label, sizeof label, "%.2f", o.score);  // calibrated: P(obstacle)
    cv::putText(out, label, {o.box.x, std::max(12, o.box.y - 4)}, cv::FONT_HERSHEY_SIMPLEX,
                0.5 * scale + 0.2, {0, 255, 255}, 1, cv::LINE_AA);
  }
  return out;
}

Status WritePngAtomically(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) return Status::Internal("cannot encode " + path);
  return WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace tod
