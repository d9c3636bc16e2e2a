// Small synthetic frames for the service tests: a grey "road" with a dark blob, encoded.
#pragma once

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace tod::server::testing {

// width x height BGR frame: sky-blue top third, grey road, a dark 12x10 blob on the road at (x, y).
inline cv::Mat3b RoadFrame(int width = 320, int height = 160, int blob_x = 150, int blob_y = 110) {
  cv::Mat3b frame(height, width, cv::Vec3b(128, 128, 128));
  frame(cv::Rect(0, 0, width, height / 3)).setTo(cv::Vec3b(200, 170, 120));
  cv::rectangle(frame, cv::Rect(blob_x, blob_y, 12, 10), cv::Scalar(20, 20, 20), cv::FILLED);
  return frame;
}

inline std::string Encode(const cv::Mat& image, const std::string& ext) {
  std::vector<uchar> bytes;
  cv::imencode(ext, image, bytes);
  return std::string(bytes.begin(), bytes.end());
}

inline std::string RoadPng(int width = 320, int height = 160) {
  return Encode(RoadFrame(width, height), ".png");
}

}  // namespace tod::server::testing
