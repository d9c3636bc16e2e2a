// "sed" edge source: OpenCV's Structured Edge Detector (ALGORITHM.md §2.1) with a model file the
// user supplies (the BSDS500 model converted to OpenCV's YAML format).
#include <fstream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>
#include <string>

#include "core/edges/edge_source.h"

namespace tod {
namespace {

class SedEdgeSource : public EdgeSource {
 public:
  explicit SedEdgeSource(cv::Ptr<cv::ximgproc::StructuredEdgeDetection> detector)
      : detector_(std::move(detector)) {}

  cv::Mat1f Compute(const cv::Mat3b& bgr) const override {
    if (bgr.empty()) return {};
    cv::Mat3f rgb;
    bgr.convertTo(rgb, CV_32F, 1.0 / 255.0);  // the detector wants float RGB in [0,1]
    cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
    cv::Mat edges;
    detector_->detectEdges(rgb, edges);
    cv::Mat1f result = edges;
    cv::min(cv::max(result, 0.f), 1.f, result);
    return result;
  }

  EdgeKind kind() const override { return EdgeKind::kSed; }

 private:
  cv::Ptr<cv::ximgproc::StructuredEdgeDetection> detector_;
};

// OpenCV's loader does not check the model's content (an empty forest divides by zero), so the
// fields it reads are checked here first.
Status CheckSedModelFields(const std::string& model_path) {
  cv::FileStorage storage;
  try {
    if (!storage.open(model_path, cv::FileStorage::READ)) {
      return Status::InvalidArgument("SED model '" + model_path +
                                     "' is not an OpenCV FileStorage (YAML/XML) file");
    }
  } catch (const cv::Exception& e) {
    return Status::InvalidArgument("SED model '" + model_path + "' cannot be parsed: " + e.what());
  }
  const cv::FileNode options = storage["options"];
  if (!options.isMap()) {
    return Status::InvalidArgument("SED model '" + model_path + "' has no 'options' map");
  }
  for (const char* name : {"numberOfTrees", "stride", "shrinkNumber", "patchSize", "patchInnerSize",
                           "numberOfGradientOrientations"}) {
    const cv::FileNode field = options[name];
    if (!field.isInt() || static_cast<int>(field) <= 0) {
      return Status::InvalidArgument("SED model '" + model_path + "': options." + name +
                                     " is missing or not a positive integer");
    }
  }
  for (const char* name : {"childs", "featureIds", "thresholds", "edgeBoundaries", "edgeBins"}) {
    const cv::FileNode field = storage[name];
    if (field.empty() || field.size() == 0) {
      return Status::InvalidArgument("SED model '" + model_path + "': field '" + name +
                                     "' is missing or empty");
    }
  }
  return Status::Ok();
}

}  // namespace

Result<std::unique_ptr<EdgeSource>> CreateSedEdgeSource(const std::string& model_path) {
  if (!std::ifstream(model_path, std::ios::binary).good()) {
    return Status::NotFound("SED model '" + model_path + "' does not exist or cannot be read");
  }
  if (Status fields = CheckSedModelFields(model_path); !fields.ok()) return fields;
  try {
    cv::Ptr<cv::ximgproc::StructuredEdgeDetection> detector =
        cv::ximgproc::createStructuredEdgeDetection(model_path);
    if (detector.empty()) {
      return Status::InvalidArgument("SED model '" + model_path + "' could not be loaded");
    }
    // A tiny run surfaces an inconsistent forest now rather than on the first request.
    auto source = std::make_unique<SedEdgeSource>(std::move(detector));
    const cv::Mat1f probe = source->Compute(cv::Mat3b(64, 64, cv::Vec3b(128, 128, 128)));
    if (probe.size() != cv::Size(64, 64)) {
      return Status::InvalidArgument("SED model '" + model_path +
                                     "' produced an edge map of the wrong size");
    }
    return std::unique_ptr<EdgeSource>(std::move(source));
  } catch (const cv::Exception& e) {
    return Status::InvalidArgument("SED model '" + model_path + "' is invalid: " + e.what());
  }
}

}  // namespace tod
