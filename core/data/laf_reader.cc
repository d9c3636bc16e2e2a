// Lost and Found reader (ALGORITHM.md §9.1). Ground truth comes from the 16-bit instanceIds PNG
// (1000 = free space, > 1000 = obstacle instance, < 1000 = ignore); the 8-bit labelIds PNG is only
// used to cross-check it, because a disagreement means a corrupt or mismatched annotation pair.
#include "core/data/laf_reader.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <system_error>
#include <utility>
#include <vector>

#include "core/data/image_file.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

constexpr int kFreeSpaceInstanceId = 1000;
constexpr const char* kImageSuffix = "_leftImg8bit.png";
constexpr const char* kInstanceSuffix = "_gtCoarse_instanceIds.png";
constexpr const char* kLabelSuffix = "_gtCoarse_labelIds.png";

std::string SizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

struct InclusiveExtent {
  int x0, y0, x1, y1;
};

// Where the three inputs of one frame came from, for error messages.
struct LafSources {
  std::string image;
  std::string instance_ids;
  std::string label_ids;
};

// Converts an annotation image to CV_32S, rejecting anything that is not a single-channel
// integer image (e.g. an RGB-encoded export).
Result<cv::Mat1i> ToIdImage(const cv::Mat& ids, const std::string& source, const char* what) {
  if (ids.empty()) return Status::InvalidArgument(std::string(what) + " is empty: " + source);
  if (ids.channels() != 1) {
    return Status::InvalidArgument(std::string(what) + " must have 1 channel, has " +
                                   std::to_string(ids.channels()) + ": " + source);
  }
  const int depth = ids.depth();
  if (depth != CV_8U && depth != CV_16U && depth != CV_32S) {
    return Status::InvalidArgument(std::string(what) +
                                   " must be an 8-bit, 16-bit or 32-bit integer image: " + source);
  }
  cv::Mat1i out;
  ids.convertTo(out, CV_32S);
  return out;
}

// The labelIds value an instanceIds value implies, as a category: 0 ignore, 1 free space,
// 2 obstacle (labelIds >= 2).
int CategoryOfInstanceId(int instance_id) {
  if (instance_id == kFreeSpaceInstanceId) return 1;
  return instance_id > kFreeSpaceInstanceId ? 2 : 0;
}
int CategoryOfLabelId(int label_id) { return std::min(label_id, 2); }

Result<Sample> BuildSample(const cv::Mat3b& image, const cv::Mat& instance_ids_raw,
                           const cv::Mat& label_ids_raw, const std::string& name,
                           const LafSources& sources) {
  if (image.empty()) return Status::InvalidArgument("image is empty: " + sources.image);
  Result<cv::Mat1i> instance_ids = ToIdImage(instance_ids_raw, sources.instance_ids, "instanceIds");
  if (!instance_ids.ok()) return instance_ids.status();
  Result<cv::Mat1i> label_ids = ToIdImage(label_ids_raw, sources.label_ids, "labelIds");
  if (!label_ids.ok()) return label_ids.status();
  if (instance_ids->size() != image.size()) {
    return Status::InvalidArgument("instanceIds size " + SizeText(*instance_ids) +
                                   " differs from image size " + SizeText(image) + ": " +
                                   sources.instance_ids + " (image " + sources.image + ")");
  }
  if (label_ids->size() != image.size()) {
    return Status::InvalidArgument("labelIds size " + SizeText(*label_ids) +
                                   " differs from image size " + SizeText(image) + ": " +
                                   sources.label_ids + " (image " + sources.image + ")");
  }

  Sample sample;
  sample.name = name;
  sample.image_path = sources.image;
  sample.image = image;
  sample.road = cv::Mat1b::zeros(image.size());
  sample.obstacle = cv::Mat1b::zeros(image.size());
  sample.ignore = cv::Mat1b::zeros(image.size());

  // One pass: masks, consistency with labelIds, and each obstacle instance's tight box.
  std::map<int, InclusiveExtent> boxes;  // instance id -> extent of its pixels
  long long disagreements = 0;
  cv::Point first_disagreement;
  int first_label = 0;
  int first_instance = 0;
  for (int y = 0; y < image.rows; ++y) {
    const int* inst_row = instance_ids->ptr<int>(y);
    const int* label_row = label_ids->ptr<int>(y);
    uchar* road_row = sample.road.ptr<uchar>(y);
    uchar* obstacle_row = sample.obstacle.ptr<uchar>(y);
    uchar* ignore_row = sample.ignore.ptr<uchar>(y);
    for (int x = 0; x < image.cols; ++x) {
      const int id = inst_row[x];
      const int category = CategoryOfInstanceId(id);
      if (category != CategoryOfLabelId(label_row[x])) {
        if (disagreements == 0) {
          first_disagreement = {x, y};
          first_label = label_row[x];
          first_instance = id;
        }
        ++disagreements;
      }
      if (category == 1) {
        road_row[x] = 255;
      } else if (category == 2) {
        obstacle_row[x] = 255;
        auto [it, inserted] = boxes.try_emplace(id, InclusiveExtent{x, y, x, y});
        if (!inserted) {
          InclusiveExtent& e = it->second;
          e.x0 = std::min(e.x0, x);
          e.x1 = std::max(e.x1, x);
          e.y1 = y;  // rows are scanned top to bottom
        }
      } else {
        ignore_row[x] = 255;
      }
    }
  }
  if (disagreements > 0) {
    return Status::InvalidArgument(
        "labelIds disagree with instanceIds at " + std::to_string(disagreements) +
        " pixel(s), first at (x=" + std::to_string(first_disagreement.x) + ", y=" +
        std::to_string(first_disagreement.y) + "): labelIds=" + std::to_string(first_label) +
        ", instanceIds=" + std::to_string(first_instance) +
        " (expected 1 <-> 1000, >= 2 <-> > 1000): " + sources.label_ids + " vs " +
        sources.instance_ids);
  }

  sample.instances.reserve(boxes.size());
  for (const auto& [id, extent] : boxes) {
    ObstacleInstance instance;
    instance.id = id;
    instance.box = Box{extent.x0, extent.y0, extent.x1 - extent.x0 + 1, extent.y1 - extent.y0 + 1};
    instance.mask = cv::Mat1b::zeros(instance.box.h, instance.box.w);
    const cv::Mat1i ids_in_box = (*instance_ids)(instance.box.rect());
    for (int y = 0; y < instance.box.h; ++y) {
      const int* row = ids_in_box.ptr<int>(y);
      uchar* out = instance.mask.ptr<uchar>(y);
      for (int x = 0; x < instance.box.w; ++x) out[x] = row[x] == id ? 255 : 0;
    }
    sample.instances.push_back(std::move(instance));
  }
  return sample;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct LafFrame {
  std::string stem;
  LafSources paths;
};

class LafDataset final : public Dataset {
 public:
  explicit LafDataset(std::vector<LafFrame> frames) : frames_(std::move(frames)) {}

  std::size_t size() const override { return frames_.size(); }
  std::string name(std::size_t i) const override {
    return i < frames_.size() ? frames_[i].stem : std::string();
  }

  Result<Sample> Load(std::size_t i) const override {
    if (Status st = CheckFrameIndex(i, frames_.size()); !st.ok()) return st;
    const LafFrame& frame = frames_[i];
    // IMREAD_COLOR gives BGR 8-bit whatever the PNG holds; the gamma chunk is not applied
    // (ALGORITHM.md §9.1: decode raw values).
    Result<cv::Mat> image = ReadImageFile(frame.paths.image, cv::IMREAD_COLOR, "image");
    if (!image.ok()) return image.status();
    // Annotations keep their raw depth: instanceIds is 16-bit, labelIds 8-bit.
    Result<cv::Mat> instance_ids =
        ReadImageFile(frame.paths.instance_ids, cv::IMREAD_UNCHANGED, "instanceIds");
    if (!instance_ids.ok()) return instance_ids.status();
    Result<cv::Mat> label_ids =
        ReadImageFile(frame.paths.label_ids, cv::IMREAD_UNCHANGED, "labelIds");
    if (!label_ids.ok()) return label_ids.status();
    return BuildSample(cv::Mat3b(*image), *instance_ids, *label_ids, frame.stem, frame.paths);
  }

 private:
  std::vector<LafFrame> frames_;
};

}  // namespace

Result<Sample> SampleFromLafAnnotation(const cv::Mat3b& image, const cv::Mat& instance_ids,
                                       const cv::Mat& label_ids, const std::string& name,
                                       const std::string& source_for_messages) {
  const LafSources sources{source_for_messages + " (image)", source_for_messages + " (instanceIds)",
                           source_for_messages + " (labelIds)"};
  return BuildSample(image, instance_ids, label_ids, name, sources);
}

bool LooksLikeLaf(const std::string& root) {
  std::error_code ec;
  return fs::is_directory(fs::path(root) / "leftImg8bit", ec) &&
         fs::is_directory(fs::path(root) / "gtCoarse", ec);
}

Result<std::unique_ptr<Dataset>> OpenLafDataset(const std::string& root, const std::string& split) {
  const fs::path image_dir = fs::path(root) / "leftImg8bit" / split;
  const fs::path annotation_dir = fs::path(root) / "gtCoarse" / split;
  std::error_code ec;
  if (!fs::is_directory(image_dir, ec)) {
    return Status::NotFound("Lost and Found image directory not found: " + image_dir.string());
  }
  if (!fs::is_directory(annotation_dir, ec)) {
    return Status::NotFound("Lost and Found annotation directory not found: " +
                            annotation_dir.string());
  }

  std::vector<fs::path> images;
  fs::recursive_directory_iterator it(image_dir, ec), end;
  if (ec) return Status::NotFound("cannot list " + image_dir.string() + ": " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) return Status::DataLoss("cannot list " + image_dir.string() + ": " + ec.message());
    if (it->is_regular_file(ec) && EndsWith(it->path().filename().string(), kImageSuffix)) {
      images.push_back(it->path());
    }
  }
  if (images.empty()) {
    return Status::NotFound("no *" + std::string(kImageSuffix) + " files under " +
                            image_dir.string());
  }
  std::sort(images.begin(), images.end());

  std::vector<LafFrame> frames;
  frames.reserve(images.size());
  const std::string suffix = kImageSuffix;
  for (const fs::path& image : images) {
    const std::string file = image.filename().string();
    LafFrame frame;
    frame.stem = file.substr(0, file.size() - suffix.size());
    // Same scene sub-path under gtCoarse/<split> as under leftImg8bit/<split>.
    const fs::path relative_dir = fs::relative(image.parent_path(), image_dir, ec);
    const fs::path gt_dir = annotation_dir / relative_dir;
    frame.paths.image = image.string();
    frame.paths.instance_ids = (gt_dir / (frame.stem + kInstanceSuffix)).string();
    frame.paths.label_ids = (gt_dir / (frame.stem + kLabelSuffix)).string();
    for (const std::string* annotation : {&frame.paths.instance_ids, &frame.paths.label_ids}) {
      if (!fs::is_regular_file(*annotation, ec)) {
        return Status::NotFound("annotation file not found: " + *annotation + " (for image " +
                                frame.paths.image + ")");
      }
    }
    frames.push_back(std::move(frame));
  }
  return std::unique_ptr<Dataset>(std::make_unique<LafDataset>(std::move(frames)));
}

}  // namespace tod
