#include "server/rest_options.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <optional>

namespace tod::server {
namespace {

// nullopt when absent; InvalidArgument when not a whole number in [low, high].
Result<std::optional<long long>> IntegerParam(const QueryParams& query, const std::string& name,
                                              long long low, long long high) {
  const auto it = query.find(name);
  if (it == query.end()) return std::optional<long long>();
  const std::string& text = it->second;
  long long value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() || value < low ||
      value > high) {
    return Status::InvalidArgument("query parameter " + name + "='" + text +
                                   "' is not a valid number in " + std::to_string(low) + ".." +
                                   std::to_string(high));
  }
  return std::optional<long long>(value);
}

Result<std::optional<double>> RealParam(const QueryParams& query, const std::string& name,
                                        double low, double high) {
  const auto it = query.find(name);
  if (it == query.end()) return std::optional<double>();
  const std::string& text = it->second;
  double value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  // from_chars accepts "nan" and "inf": the explicit finiteness test refuses them.
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() ||
      !std::isfinite(value) || value < low || value > high) {
    return Status::InvalidArgument("query parameter " + name + "='" + text +
                                   "' is not a valid number in [" + std::to_string(low) + ", " +
                                   std::to_string(high) + "]");
  }
  return std::optional<double>(value);
}

}  // namespace

Status ParseDetectQuery(const QueryParams& query, InferenceRequest* inference,
                        std::string* frame_id) {
  const Result<std::optional<long long>> proposals =
      IntegerParam(query, "max_proposals", 0, kMaxRequestProposals);
  if (!proposals.ok()) return proposals.status();
  if (*proposals) inference->options.max_proposals = static_cast<int>(**proposals);

  const Result<std::optional<double>> threshold = RealParam(query, "obstacle_threshold", 0, 1);
  if (!threshold.ok()) return threshold.status();
  if (*threshold) inference->options.obstacle_threshold = static_cast<float>(**threshold);

  const Result<std::optional<double>> min_score = RealParam(query, "min_obstacle_score", 0, 1);
  if (!min_score.ok()) return min_score.status();
  if (*min_score) inference->options.min_obstacle_score = static_cast<float>(**min_score);

  const Result<std::optional<long long>> budget =
      IntegerParam(query, "budget_ms", 1, kMaxRequestBudgetMs);
  if (!budget.ok()) return budget.status();
  if (*budget) inference->options.budget_ms = static_cast<double>(**budget);

  if (const auto map = query.find("map"); map != query.end()) {
    if (map->second == "none") {
      inference->encode_map_png = false;
    } else if (map->second == "png") {
      inference->encode_map_png = true;
    } else {
      return Status::InvalidArgument("query parameter map='" + map->second +
                                     "': expected png or none");
    }
  }

  if (const auto kind = query.find("map_kind"); kind != query.end()) {
    const std::optional<MapKind> parsed = ParseMapKind(kind->second);
    if (!parsed)
      return Status::InvalidArgument("query parameter map_kind='" + kind->second +
                                     "': expected normalized or calibrated");
    inference->options.map_kind = *parsed;
  }

  const Result<std::optional<long long>> timeout_ms =
      IntegerParam(query, "timeout_ms", 0, kMaxRestTimeoutMs);
  if (!timeout_ms.ok()) return timeout_ms.status();
  if (*timeout_ms && **timeout_ms > 0) {
    inference->deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(**timeout_ms);
  }
  if (const auto calibrate = query.find("calibrate"); calibrate != query.end()) {
    if (calibrate->second != "true" && calibrate->second != "false") {
      return Status::InvalidArgument("query parameter calibrate='" + calibrate->second +
                                     "': expected true or false");
    }
    inference->options.calibrate = calibrate->second == "true";
  }
  // Bounded and checked by the engine at admission, as on gRPC (CheckCameraId).
  if (const auto camera = query.find("camera_id"); camera != query.end()) {
    inference->camera_id = camera->second;
  }
  if (const auto id = query.find("frame_id"); id != query.end()) *frame_id = id->second;
  if (const auto model = query.find("model"); model != query.end()) {
    inference->model = model->second;
  }
  return Status::Ok();
}

}  // namespace tod::server
