#include "client/detect_outputs.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "client/image_files.h"
#include "client/overlay.h"
#include "proto/json/message_json.h"

namespace tod::client {

Status WriteDetectOutputs(const std::string& out_dir, const std::string& image_path,
                          const std::string& image_bytes, const tod::v1::DetectResponse& response) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(out_dir, error);
  if (error) return Status::NotFound(out_dir + ": cannot create folder: " + error.message());
  const std::string stem = (fs::path(out_dir) / fs::path(image_path).stem()).string();

  tod::v1::DetectResponse without_map = response;
  without_map.mutable_probability_map()->clear_png();
  const std::string json = proto::MessageToJson(without_map, proto::JsonLayout::kIndented);
  if (Status s = WriteFileBytes(stem + ".json", json + "\n"); !s.ok()) return s;

  const std::string& png = response.probability_map().png();
  cv::Mat1b probability;
  if (!png.empty()) {
    if (Status s = WriteFileBytes(stem + ".map.png", png); !s.ok()) return s;
    const std::vector<uchar> encoded(png.begin(), png.end());
    probability = cv::imdecode(encoded, cv::IMREAD_GRAYSCALE);
  }
  const std::vector<uchar> encoded_image(image_bytes.begin(), image_bytes.end());
  const cv::Mat image = cv::imdecode(encoded_image, cv::IMREAD_COLOR);
  if (image.empty()) return Status::InvalidArgument(image_path + ": cannot decode for overlay");
  const cv::Mat3b overlay = DrawOverlay(image, response, probability);
  if (!cv::imwrite(stem + ".overlay.png", overlay)) {
    return Status::DataLoss(stem + ".overlay.png: cannot write");
  }
  return Status::Ok();
}

}  // namespace tod::client
