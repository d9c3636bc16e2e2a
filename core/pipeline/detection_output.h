// What a person and a program get from one detection: the JSON document of `tod detect`, the
// probability map as an 8-bit PNG (255 = 1.0) and the overlay image. Shared by the CLI and the
// service so every front end draws and encodes the same way.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "core/base/status.h"
#include "core/pipeline/detector.h"

namespace tod {

// {"image","width","height","proposals":[{"x","y","w","h","score","ordr","obdr"}],
//  "obstacles":[{"x","y","w","h","area","peak","mean"}],"timing_ms":{stage: ms, "total": ms}}
nlohmann::json DetectionToJson(const Detection& detection, const std::string& image_name);
// The geometry the detection stood on: source, horizon rows, shift, road region, fallback (the
// JSON `tod detect` writes; the server's Geometry message has the same fields).
nlohmann::json GeometryToJson(const Detection& d);

// Probability in [0,1] to 8-bit (255 = 1.0).
cv::Mat1b ProbabilityTo8Bit(const cv::Mat1f& probability);

// The frame with the probability map as a red heat overlay, obstacle boxes in yellow with their
// peak probability, and the top proposals as thin cyan boxes.
cv::Mat3b DrawOverlay(const cv::Mat3b& bgr, const Detection& detection, int top_proposals = 10);

// Encodes `image` as PNG and writes it atomically (temporary file + rename), so a reader never
// sees half a picture.
Status WritePngAtomically(const std::string& path, const cv::Mat& image);

}  // namespace tod
