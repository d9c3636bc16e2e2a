// The query parameters of POST /v1/detect and /v1/probability-map, parsed and range-checked:
//   max_proposals  integer 0..10000        obstacle_threshold  number in [0, 1]
//   map            png | none              timeout_ms          integer 0..3600000 (0: none)
//   budget_ms      integer 1..600000 (lowers the server's frame budget)
//   frame_id       text                    model               a loaded model's name
//   camera_id      printable ASCII, at most 128 bytes (the camera whose horizon is kept)
//   calibrate      true | false (self-calibration of the road geometry; default true)
// A value out of range or not a number is an InvalidArgument naming the parameter; nothing can
// overflow (numbers are parsed into wide types and checked before use). The bounds gRPC shares
// (max_proposals, budget_ms) are the engine's: kMaxRequestProposals, kMaxRequestBudgetMs.
#pragma once

#include <map>
#include <string>

#include "core/base/status.h"
#include "server/core/inference_engine.h"

namespace tod::server {

inline constexpr long long kMaxRestTimeoutMs = 3'600'000;  // one hour

using QueryParams = std::map<std::string, std::string, std::less<>>;

// Fills the options, map choice and deadline of `inference` and `frame_id` (left as it is when
// the query has none).
Status ParseDetectQuery(const QueryParams& query, InferenceRequest* inference,
                        std::string* frame_id);

}  // namespace tod::server
