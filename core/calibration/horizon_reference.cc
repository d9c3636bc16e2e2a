#include "core/calibration/horizon_reference.h"

#include <algorithm>
#include <cmath>

namespace tod {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

nlohmann::json HorizonReference::ToJson() const {
  return {{"row", row}, {"spread", spread}, {"frames", frames}, {"frame_height", frame_height}};
}

Result<HorizonReference> HorizonReference::FromJson(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains("row") || !j["row"].is_number() ||
      !j.contains("frame_height") || !j["frame_height"].is_number_integer())
    return Status::InvalidArgument("horizon_reference needs a number row and frame_height");
  HorizonReference r;
  r.row = j["row"].get<double>();
  r.spread = j.value("spread", 0.0);
  r.frames = j.value("frames", 0);
  r.frame_height = j["frame_height"].get<int>();
  if (!std::isfinite(r.row) || r.frame_height <= 0 || r.spread < 0)
    return Status::InvalidArgument("horizon_reference out of range");
  return r;
}

Result<HorizonReference> ReferenceFromEstimates(const std::vector<HorizonEstimate>& estimates,
                                                int frame_height, int min_frames) {
  std::vector<double> rows;
  for (const HorizonEstimate& e : estimates)
    if (e.found) rows.push_back(e.row);
  if (static_cast<int>(rows.size()) < min_frames)
    return Status::FailedPrecondition("the horizon was found on " + std::to_string(rows.size()) +
                                      " of " + std::to_string(estimates.size()) +
                                      " training frames (at least " + std::to_string(min_frames) +
                                      " needed for a reference)");
  HorizonReference r;
  r.row = Median(rows);
  std::vector<double> deviation;
  for (double row : rows) deviation.push_back(std::abs(row - r.row));
  r.spread = Median(deviation);
  r.frames = static_cast<int>(rows.size());
  r.frame_height = frame_height;
  return r;
}

}  // namespace tod
