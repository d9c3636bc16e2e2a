// The trained pipeline, loaded once from a model bundle and shared by every worker: Detect() is
// const and thread-safe. This is the only header the server and the CLI need.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/base/status.h"
#include "core/base/types.h"
#include "core/calibration/horizon_choice.h"

namespace tod {

// Which obstacle-occupied probability map a detection returns (and thresholds for obstacles).
enum class MapKind {
  // The paper's map (§7): the top half of the boxes summed, divided by the frame's maximum. Its
  // peak is 1 on every frame; the paper's metrics are defined on it.
  kNormalized,
  // Per pixel, the largest calibrated score of the fused boxes over it, each weighted by the share
  // of the pixel's superpixel the box holds (probability_map.h): comparable across frames, so a
  // threshold means the same on an empty road and a busy one.
  kCalibrated,
};
// "normalized" / "calibrated", the name the REST query, the CLI and the JSON use.
const char* MapKindName(MapKind kind);
std::optional<MapKind> ParseMapKind(std::string_view name);

struct DetectOptions {
  int max_proposals = 100;          // proposals returned (the map always uses all of them)
  float obstacle_threshold = 0.5f;  // obstacle mask = P > threshold
  // Components whose calibrated score (DetectedObstacle::score) is below this are not reported:
  // an empty road reports no obstacle.
  float min_obstacle_score = 0.5f;
  // Components of fewer pixels are not reported either: the obstacle benchmarks void ground-truth
  // components under 10 px (SegmentMeIfYouCan), so a smaller one can match no obstacle, and a
  // single pixel over the threshold (a peak where box corners stack) is not an obstacle.
  int min_obstacle_area = 10;
  bool want_probability_map = true;
  MapKind map_kind = MapKind::kNormalized;
  // Frame budget in ms from the Detect call (frame_budget.h): past its stage shares, proposals
  // and regression degrade in a defined way and Detection::degraded_stages names them. <= 0: no
  // budget.
  double budget_ms = 0;
  // Cores this request may use: the window scans, features and regressors split their work
  // over this many threads. The result does not depend on it (unless a budget cuts work short).
  int threads = 1;
  // Asked between stages (after edges, superpixels, occlusion, proposals, features, regression);
  // when it returns a non-OK Status (Cancelled, DeadlineExceeded, ...) Detect stops and returns
  // it. A stage itself is never interrupted, so the hook only has to be cheap and thread-safe.
  // Empty: run to the end.
  std::function<Status()> cancelled;
  // Self-calibration (issue 48): the frame's horizon is estimated and the bundle's regions,
  // size filter and ground-plane features are moved to it (Detection::horizon says what was
  // used). With `camera`, the camera's median over the frames it sent is used instead of the
  // frame's own estimate, and this frame's estimate joins it.
  bool calibrate = true;
  std::shared_ptr<CameraTrack> camera;
};

struct Proposal {
  Box box;
  float fused = 0.f;  // F = ORDR + beta1 * OBDR (0 when gated out)
  float ordr = 0.f;
  float obdr = 0.f;
};

struct DetectedObstacle {
  Box box;
  long long area = 0;  // pixels of the connected component
  float peak_probability = 0.f;
  float mean_probability = 0.f;
  float evidence = 0.f;  // largest fused score F of the map's boxes overlapping it
  float score = 0.f;     // calibrated probability that it is an obstacle (= evidence if the
                         // bundle has no calibration)
};

struct Detection {
  int width = 0;
  int height = 0;
  std::vector<Proposal> proposals;  // descending fused score, at most max_proposals
  std::vector<DetectedObstacle> obstacles;
  cv::Mat1f probability;                    // image size, [0,1]; empty unless requested
  MapKind map_kind = MapKind::kNormalized;  // the kind of `probability` (and of the obstacles)
  StageTimes timings;                       // per stage, in pipeline order, milliseconds
  // Stages the frame budget cut short ("proposals", "regression"); empty: the full result.
  std::vector<std::string> degraded_stages;
  bool degraded() const { return !degraded_stages.empty(); }
  // The horizon the geometry stood on and where it came from (bundle, frame, camera).
  HorizonUse horizon;
  Box road_region;  // R1 on this frame, after the horizon's shift
};

struct ModelInfo {
  std::string name;     // bundle directory name
  std::string version;  // bundle's own version string
  int format_version = 0;
  std::string created;      // ISO 8601
  std::string trained_on;   // dataset description
  std::string edge_source;  // "pixel_forest", "gradient", "sed"
  nlohmann::json manifest;  // the whole manifest
};

class Detector {
 public:
  virtual ~Detector() = default;
  // Loads and checks a bundle; errors name the file and the problem.
  static Result<std::shared_ptr<const Detector>> Load(const std::string& model_dir);

  virtual Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options) const = 0;
  virtual const ModelInfo& info() const = 0;
};

}  // namespace tod
