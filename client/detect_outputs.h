// What tod_client writes per image: <stem>.json (the response as indented JSON, proto/json/,
// map bytes left out), <stem>.map.png (the probability map, when returned) and
// <stem>.overlay.png.
#pragma once

#include <string>

#include "core/base/status.h"
#include "tod/v1/obstacle_discovery.pb.h"

namespace tod::client {

// `image_bytes` is the encoded frame that was sent (for the overlay).
Status WriteDetectOutputs(const std::string& out_dir, const std::string& image_path,
                          const std::string& image_bytes, const tod::v1::DetectResponse& response);

}  // namespace tod::client
