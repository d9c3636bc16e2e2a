#include "core/data/masks_reader.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "core/data/image_file.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

constexpr uchar kNotObstacle = 0;
constexpr uchar kObstacle = 1;
constexpr uchar kVoid = 255;

struct MaskFrame {
  std::string stem;
  std::string image;
  std::string mask;
};

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool IsImageExtension(const std::string& extension) {
  const std::string e = Lower(extension);
  return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".webp";
}

// Stems in natural order ("2" before "10"), so frame numbers read as numbers in every listing.
struct NaturalLess {
  bool operator()(const std::string& a, const std::string& b) const {
    std::size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
      if (std::isdigit(static_cast<unsigned char>(a[i])) &&
          std::isdigit(static_cast<unsigned char>(b[j]))) {
        std::size_t i_end = i, j_end = j;
        while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end]))) ++i_end;
        while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end]))) ++j_end;
        // Compare digit runs by value: strip leading zeros, then longer is larger.
        std::size_t ia = i, jb = j;
        while (ia + 1 < i_end && a[ia] == '0') ++ia;
        while (jb + 1 < j_end && b[jb] == '0') ++jb;
        if (i_end - ia != j_end - jb) return i_end - ia < j_end - jb;
        if (const int c = a.compare(ia, i_end - ia, b, jb, j_end - jb); c != 0) return c < 0;
        i = i_end;
        j = j_end;
        continue;
      }
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
    return a.size() - i < b.size() - j || (a.size() - i == b.size() - j && a < b);
  }
};

// The mask of `stem`: <stem>.png, else <stem>_labels_semantic.png; empty when neither exists.
std::string MaskPathFor(const fs::path& mask_dir, const std::string& stem) {
  std::error_code ec;
  for (const std::string& name : {stem + ".png", stem + "_labels_semantic.png"}) {
    const fs::path p = mask_dir / name;
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  return {};
}

// split -> stems, from `train <stem>` / `test <stem>` lines.
Result<std::map<std::string, std::set<std::string>>> ReadSplitFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::NotFound("cannot open split file " + path);
  std::map<std::string, std::set<std::string>> splits;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::string split, stem, extra;
    if (!(fields >> split)) continue;  // blank or comment
    if (!(fields >> stem) || (fields >> extra)) {
      return Status::InvalidArgument(path + ":" + std::to_string(line_number) +
                                     ": expected '<split> <stem>', got '" + line + "'");
    }
    splits[split].insert(stem);
  }
  return splits;
}

class MasksDataset final : public Dataset {
 public:
  explicit MasksDataset(std::vector<MaskFrame> frames) : frames_(std::move(frames)) {}

  std::size_t size() const override { return frames_.size(); }
  std::string name(std::size_t i) const override {
    return i < frames_.size() ? frames_[i].stem : std::string();
  }

  Result<Sample> Load(std::size_t i) const override {
    if (Status st = CheckFrameIndex(i, frames_.size()); !st.ok()) return st;
    const MaskFrame& frame = frames_[i];
    Result<cv::Mat> image = ReadImageFile(frame.image, cv::IMREAD_COLOR, "image");
    if (!image.ok()) return image.status();
    Result<cv::Mat> mask = ReadImageFile(frame.mask, cv::IMREAD_UNCHANGED, "mask");
    if (!mask.ok()) return mask.status();
    Result<Sample> sample =
        SampleFromObstacleMask(cv::Mat3b(*image), *mask, frame.stem, frame.mask);
    if (sample.ok()) sample->image_path = frame.image;
    return sample;
  }

 private:
  std::vector<MaskFrame> frames_;
};

// Every image under images/ with its mask, sorted by stem.
Result<std::vector<MaskFrame>> ListFrames(const fs::path& image_dir, const fs::path& mask_dir) {
  std::error_code ec;
  std::map<std::string, std::string, NaturalLess> images;  // stem -> path
  for (fs::directory_iterator it(image_dir, ec), end; it != end; it.increment(ec)) {
    if (ec) break;
    const fs::path& p = it->path();
    if (!it->is_regular_file(ec) || !IsImageExtension(p.extension().string())) continue;
    const std::string stem = p.stem().string();
    if (auto [at, inserted] = images.emplace(stem, p.string()); !inserted) {
      return Status::InvalidArgument("two images share the stem '" + stem + "': " + at->second +
                                     " and " + p.string());
    }
  }
  if (ec) return Status::NotFound("cannot list " + image_dir.string() + ": " + ec.message());
  std::vector<MaskFrame> frames;
  for (const auto& [stem, image] : images) {
    const std::string mask = MaskPathFor(mask_dir, stem);
    if (mask.empty()) {
      return Status::NotFound("no mask for image " + image + " (looked for " +
                              (mask_dir / (stem + ".png")).string() + " and " +
                              (mask_dir / (stem + "_labels_semantic.png")).string() + ")");
    }
    frames.push_back({stem, image, mask});
  }
  return frames;
}

}  // namespace

Result<Sample> SampleFromObstacleMask(const cv::Mat3b& image, const cv::Mat& mask,
                                      const std::string& name, const std::string& mask_source) {
  if (image.empty()) return Status::InvalidArgument("image is empty (mask " + mask_source + ")");
  if (mask.channels() != 1 || mask.depth() != CV_8U) {
    return Status::InvalidArgument(
        "mask must be a single-channel 8-bit image with values 0, 1, "
        "255: " +
        mask_source);
  }
  if (mask.size() != image.size()) {
    return Status::InvalidArgument("mask size " + std::to_string(mask.cols) + "x" +
                                   std::to_string(mask.rows) + " differs from image size " +
                                   std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                   ": " + mask_source);
  }
  Sample sample;
  sample.name = name;
  sample.image = image;
  sample.free_space = FreeSpace::kNotObstacle;
  const cv::Mat1b labels(mask);
  for (int y = 0; y < labels.rows; ++y) {
    const uchar* row = labels[y];
    for (int x = 0; x < labels.cols; ++x) {
      if (row[x] != kNotObstacle && row[x] != kObstacle && row[x] != kVoid) {
        return Status::InvalidArgument("mask value " + std::to_string(row[x]) +
                                       " at (x=" + std::to_string(x) + ", y=" + std::to_string(y) +
                                       ") is none of 0 (not an obstacle), 1 (obstacle), 255 "
                                       "(void): " +
                                       mask_source);
      }
    }
  }
  sample.ignore = labels == kVoid;
  sample.road = labels == kNotObstacle;
  sample.obstacle = cv::Mat1b::zeros(labels.size());

  cv::Mat1i components;
  cv::Mat1i stats;
  cv::Mat1d centroids;
  const int count =
      cv::connectedComponentsWithStats(labels == kObstacle, components, stats, centroids, 8);
  for (int c = 1; c < count; ++c) {
    const Box box{stats(c, cv::CC_STAT_LEFT), stats(c, cv::CC_STAT_TOP),
                  stats(c, cv::CC_STAT_WIDTH), stats(c, cv::CC_STAT_HEIGHT)};
    const cv::Mat1b member = components(box.rect()) == c;
    // Specks are label noise, not obstacles one could find: void, so neither side is scored.
    if (stats(c, cv::CC_STAT_AREA) < kMinInstancePixels) {
      sample.ignore(box.rect()).setTo(255, member);
      continue;
    }
    sample.obstacle(box.rect()).setTo(255, member);
    ObstacleInstance instance;
    instance.id = c;
    instance.box = box;
    instance.mask = member.clone();
    sample.instances.push_back(std::move(instance));
  }
  return sample;
}

bool LooksLikeMasks(const std::string& root) {
  std::error_code ec;
  return fs::is_directory(fs::path(root) / "images", ec) &&
         fs::is_directory(fs::path(root) / "labels_masks", ec);
}

Result<std::unique_ptr<Dataset>> OpenMasksDataset(const std::string& root, const std::string& split,
                                                  const std::string& split_file) {
  const fs::path image_dir = fs::path(root) / "images";
  const fs::path mask_dir = fs::path(root) / "labels_masks";
  std::error_code ec;
  for (const fs::path& dir : {image_dir, mask_dir}) {
    if (!fs::is_directory(dir, ec)) return Status::NotFound("directory not found: " + dir.string());
  }
  Result<std::vector<MaskFrame>> listed = ListFrames(image_dir, mask_dir);
  if (!listed.ok()) return listed.status();
  std::vector<MaskFrame> frames = std::move(*listed);
  if (frames.empty()) {
    return Status::NotFound("no .png/.jpg/.webp images under " + image_dir.string());
  }

  std::string split_path = split_file;
  if (split_path.empty() && fs::is_regular_file(fs::path(root) / "split.txt", ec)) {
    split_path = (fs::path(root) / "split.txt").string();
  }
  if (split_path.empty()) {
    return std::unique_ptr<Dataset>(std::make_unique<MasksDataset>(std::move(frames)));
  }
  auto splits = ReadSplitFile(split_path);
  if (!splits.ok()) return splits.status();
  std::set<std::string> wanted;
  for (const auto& [name, stems] : *splits)
    if (split == "all" || name == split) wanted.insert(stems.begin(), stems.end());
  std::set<std::string> present;
  for (const MaskFrame& f : frames) present.insert(f.stem);
  for (const std::string& stem : wanted) {
    if (!present.count(stem)) {
      return Status::NotFound(split_path + " lists '" + stem + "' but " + image_dir.string() +
                              " has no image with that stem");
    }
  }
  std::erase_if(frames, [&](const MaskFrame& f) { return !wanted.count(f.stem); });
  return std::unique_ptr<Dataset>(std::make_unique<MasksDataset>(std::move(frames)));
}

}  // namespace tod
