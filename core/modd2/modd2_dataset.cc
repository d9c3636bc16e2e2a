// OpenModd2Dataset / LooksLikeModd2: the MODDv2 directory layout (MODD2-FORMAT.md "Layout"):
//   <root>/video_data/<seq>/{frames,framesRectified}/%08dL.jpg
//   <root>/annotationsV2[_rectified]/<seq>/ground_truth/%08dL.mat
// The benchmark evaluates frames S+1..E of a sequence named kopeNN-CC-SSSSSSSS-EEEEEEEE; the
// annotation of frame S has no image and is skipped.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <set>
#include <utility>

#include "core/modd2/modd2_reader.h"
#include "core/modd2/modd2_split.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

struct Modd2Frame {
  std::string name;  // "<seq>_<stem>"
  std::string image_path;
  std::string annotation_path;
};

class Modd2Dataset final : public Dataset {
 public:
  Modd2Dataset(std::vector<Modd2Frame> frames, int min_obstacle_area)
      : frames_(std::move(frames)), min_obstacle_area_(min_obstacle_area) {}

  std::size_t size() const override { return frames_.size(); }
  std::string name(std::size_t i) const override { return frames_.at(i).name; }

  Result<Sample> Load(std::size_t i) const override {
    if (i >= frames_.size()) {
      return Status::InvalidArgument("MODDv2 frame index " + std::to_string(i) +
                                     " out of range (size " + std::to_string(frames_.size()) + ")");
    }
    const Modd2Frame& frame = frames_[i];
    const cv::Mat image = cv::imread(frame.image_path, cv::IMREAD_COLOR);
    if (image.empty()) return Status::DataLoss(frame.image_path + ": cannot decode the image");
    Result<Modd2Annotation> annotation = ReadModd2Annotation(frame.annotation_path);
    if (!annotation.ok()) return annotation.status();
    Sample sample =
        SampleFromModd2Annotation(*annotation, cv::Mat3b(image), frame.name, min_obstacle_area_);
    sample.image_path = frame.image_path;
    return sample;
  }

 private:
  std::vector<Modd2Frame> frames_;
  int min_obstacle_area_;
};

bool IsDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

bool IsFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

// The annotation directory: annotationsV2[_rectified]; the raw annotations zip unpacks as
// annotations_v2_redone/, accepted too.
std::optional<fs::path> AnnotationRoot(const fs::path& root, bool rectified) {
  const std::vector<std::string> candidates =
      rectified ? std::vector<std::string>{"annotationsV2_rectified"}
                : std::vector<std::string>{"annotationsV2", "annotations_v2_redone"};
  for (const std::string& c : candidates) {
    if (IsDirectory(root / c)) return root / c;
  }
  return std::nullopt;
}

// Frame range (S, E] from "kopeNN-CC-SSSSSSSS-EEEEEEEE"; nullopt for other names.
std::optional<std::pair<long long, long long>> FrameRange(const std::string& sequence) {
  const std::size_t last_dash = sequence.rfind('-');
  if (last_dash == std::string::npos || last_dash == 0) return std::nullopt;
  const std::size_t prev_dash = sequence.rfind('-', last_dash - 1);
  if (prev_dash == std::string::npos) return std::nullopt;
  const std::string start = sequence.substr(prev_dash + 1, last_dash - prev_dash - 1);
  const std::string end = sequence.substr(last_dash + 1);
  const auto all_digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 12 &&
           std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  if (!all_digits(start) || !all_digits(end)) return std::nullopt;
  return std::make_pair(std::stoll(start), std::stoll(end));
}

// "%08dL.mat" -> frame number; nullopt for other files.
std::optional<long long> LeftFrameNumber(const std::string& filename) {
  const std::string suffix = "L.mat";
  if (filename.size() <= suffix.size() || filename.size() > suffix.size() + 12 ||
      filename.compare(filename.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return std::nullopt;
  }
  const std::string digits = filename.substr(0, filename.size() - suffix.size());
  if (!std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return std::nullopt;
  }
  return std::stoll(digits);
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& n : names) joined += (joined.empty() ? "" : ", ") + n;
  return joined;
}

std::string OverrideHint(const fs::path& root) {
  return "; set Modd2Options::train_sequences / test_sequences or write a split file (" +
         (root / kModd2SplitFileName).string() + ") to use other sequences";
}

Result<std::vector<Modd2Frame>> ListSequenceFrames(const fs::path& root,
                                                   const fs::path& annotation_root,
                                                   const std::string& sequence, bool rectified) {
  const fs::path ground_truth = annotation_root / sequence / "ground_truth";
  const fs::path frames_dir =
      root / "video_data" / sequence / (rectified ? "framesRectified" : "frames");
  if (!IsDirectory(ground_truth)) {
    return Status::NotFound(ground_truth.string() + ": annotation directory of sequence " +
                            sequence + " not found");
  }
  if (!IsDirectory(frames_dir)) {
    return Status::NotFound(frames_dir.string() + ": image directory of sequence " + sequence +
                            " not found");
  }
  const auto range = FrameRange(sequence);
  std::vector<std::pair<long long, std::string>> annotated;  // frame number, file name
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(ground_truth, ec)) {
    const std::string filename = entry.path().filename().string();
    const std::optional<long long> number = LeftFrameNumber(filename);
    if (!number) continue;
    if (range && (*number <= range->first || *number > range->second)) continue;
    annotated.emplace_back(*number, filename);
  }
  if (ec) return Status::NotFound(ground_truth.string() + ": cannot list: " + ec.message());
  if (annotated.empty()) {
    return Status::NotFound(ground_truth.string() + ": no %08dL.mat annotation files" +
                            (range ? " for frames " + std::to_string(range->first + 1) + ".." +
                                         std::to_string(range->second)
                                   : std::string()));
  }
  std::sort(annotated.begin(), annotated.end());
  std::vector<Modd2Frame> frames;
  frames.reserve(annotated.size());
  for (const auto& [number, filename] : annotated) {
    const std::string stem = filename.substr(0, filename.size() - 4);  // "00004501L"
    const fs::path image = frames_dir / (stem + ".jpg");
    const fs::path annotation = ground_truth / filename;
    if (!IsFile(image)) {
      return Status::NotFound(annotation.string() + ": frame without an image (" + image.string() +
                              " is missing)");
    }
    frames.push_back({sequence + "_" + stem, image.string(), annotation.string()});
  }
  return frames;
}

}  // namespace

bool LooksLikeModd2(const std::string& root) {
  const fs::path r(root);
  return IsDirectory(r / "video_data") &&
         (AnnotationRoot(r, false).has_value() || AnnotationRoot(r, true).has_value());
}

Result<std::unique_ptr<Dataset>> OpenModd2Dataset(const std::string& root, const std::string& split,
                                                  const Modd2Options& options) {
  const fs::path root_path(root);
  if (!IsDirectory(root_path)) return Status::NotFound(root + ": MODDv2 root directory not found");
  if (!IsDirectory(root_path / "video_data")) {
    return Status::NotFound((root_path / "video_data").string() +
                            ": not found (expected the MODDv2 layout video_data/<seq>/...)");
  }
  const std::optional<fs::path> annotation_root = AnnotationRoot(root_path, options.rectified);
  if (!annotation_root) {
    return Status::NotFound(root + ": no " +
                            (options.rectified ? "annotationsV2_rectified/"
                                               : "annotationsV2/ (or annotations_v2_redone/)") +
                            " directory");
  }

  // Which split: the caller's lists, else the root's split file, else the repository default.
  Modd2Split sequences_split;
  const bool from_options = !options.train_sequences.empty() || !options.test_sequences.empty();
  if (from_options) {
    sequences_split.source = "the split given in Modd2Options";
    sequences_split.train = options.train_sequences;
    sequences_split.test = options.test_sequences;
  } else if (IsFile(root_path / kModd2SplitFileName)) {
    Result<Modd2Split> from_file = ReadModd2SplitFile((root_path / kModd2SplitFileName).string());
    if (!from_file.ok()) return from_file.status();
    sequences_split = std::move(from_file).value();
  } else {
    sequences_split = DefaultModd2Split();
  }
  Result<std::vector<std::string>> wanted = SelectModd2Sequences(sequences_split, split);
  if (!wanted.ok()) return wanted.status();
  if (wanted->empty()) {
    return Status::InvalidArgument("MODDv2 split '" + split + "' of " + sequences_split.source +
                                   " lists no sequences");
  }

  std::set<std::string> on_disk;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(root_path / "video_data", ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.empty() && name[0] != '.' && IsDirectory(entry.path())) on_disk.insert(name);
  }
  if (ec) return Status::NotFound(root + "/video_data: cannot list: " + ec.message());

  // With an implicit split (default or split file), sequences it does not know mean the root and
  // the split disagree (renamed folders, another dataset version): say so instead of guessing.
  if (!from_options) {
    Result<std::vector<std::string>> known = SelectModd2Sequences(sequences_split, "all");
    std::vector<std::string> unknown;
    for (const std::string& name : on_disk) {
      if (std::find(known->begin(), known->end(), name) == known->end()) unknown.push_back(name);
    }
    if (!unknown.empty()) {
      return Status::InvalidArgument(
          (root_path / "video_data").string() + " holds sequences " + sequences_split.source +
          " does not know: " + JoinNames(unknown) + OverrideHint(root_path));
    }
  }
  std::vector<std::string> missing;
  for (const std::string& name : *wanted) {
    if (on_disk.count(name) == 0) missing.push_back(name);
  }
  if (!missing.empty()) {
    return Status::NotFound(root + ": split '" + split + "' of " + sequences_split.source +
                            " needs " + std::to_string(missing.size()) + " of its " +
                            std::to_string(wanted->size()) +
                            " sequences that are missing under video_data/: " + JoinNames(missing) +
                            OverrideHint(root_path));
  }

  std::vector<Modd2Frame> frames;
  for (const std::string& sequence : *wanted) {
    Result<std::vector<Modd2Frame>> sequence_frames =
        ListSequenceFrames(root_path, *annotation_root, sequence, options.rectified);
    if (!sequence_frames.ok()) return sequence_frames.status();
    frames.insert(frames.end(), sequence_frames->begin(), sequence_frames->end());
  }
  return std::unique_ptr<Dataset>(
      std::make_unique<Modd2Dataset>(std::move(frames), options.min_obstacle_area));
}

}  // namespace tod
