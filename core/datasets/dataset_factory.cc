#include "core/datasets/dataset_factory.h"

#include <algorithm>

#include "core/data/laf_reader.h"
#include "core/data/masks_reader.h"
#include "core/modd2/modd2_reader.h"

namespace tod {

Result<std::string> DetectDatasetFormat(const std::string& root) {
  if (LooksLikeLaf(root)) return std::string("laf");
  if (LooksLikeMasks(root)) return std::string("masks");
  if (LooksLikeModd2(root)) return std::string("modd2");
  return Status::NotFound(root +
                          ": neither the Lost and Found layout (leftImg8bit/, gtCoarse/), the "
                          "obstacle-mask layout (images/, labels_masks/) nor the MODDv2 layout "
                          "(video_data/, annotationsV2/); use --format");
}

namespace {

Result<std::string> ResolveFormat(const DatasetSpec& spec) {
  if (spec.format == "auto") return DetectDatasetFormat(spec.root);
  if (spec.format == "laf" || spec.format == "masks" || spec.format == "modd2") return spec.format;
  return Status::InvalidArgument("unknown dataset format '" + spec.format +
                                 "' (auto, laf, masks, modd2)");
}

}  // namespace

Result<std::unique_ptr<Dataset>> OpenDataset(const DatasetSpec& spec) {
  auto format = ResolveFormat(spec);
  if (!format.ok()) return format.status();
  if (!spec.split_file.empty() && *format != "masks") {
    return Status::InvalidArgument("--split-file applies to the masks format only (" + spec.root +
                                   " is " + *format + ")");
  }
  if (*format == "laf") return OpenLafDataset(spec.root, spec.split);
  if (*format == "masks") return OpenMasksDataset(spec.root, spec.split, spec.split_file);
  return OpenModd2Dataset(spec.root, spec.split);
}

std::vector<int> SpreadIndices(int total, int count) {
  const long long n = count > 0 ? std::min(total, count) : total;
  std::vector<int> out;
  for (long long j = 0; j < n; ++j) out.push_back(static_cast<int>(j * total / n));
  return out;
}

Result<FrameSelection> SelectFrames(const DatasetSpec& spec) {
  auto format = ResolveFormat(spec);
  if (!format.ok()) return format.status();
  DatasetSpec resolved = spec;
  resolved.format = *format;
  auto dataset = OpenDataset(resolved);
  if (!dataset.ok()) return dataset.status();
  FrameSelection out;
  out.format = *format;
  out.dataset = std::move(*dataset);
  const int total = static_cast<int>(out.dataset->size());
  if (total == 0)
    return Status::InvalidArgument(spec.root + ": the " + spec.split + " split is empty");
  out.frames = SpreadIndices(total, spec.max_frames);
  out.source.assign(out.frames.size(), 0);
  return out;
}

namespace {

// The frames of several selections, one after the other.
class ConcatenatedDataset final : public Dataset {
 public:
  explicit ConcatenatedDataset(std::vector<FrameSelection> parts) : parts_(std::move(parts)) {
    for (std::size_t p = 0; p < parts_.size(); ++p)
      for (int frame : parts_[p].frames) index_.emplace_back(p, frame);
  }
  std::size_t size() const override { return index_.size(); }
  std::string name(std::size_t i) const override {
    if (i >= index_.size()) return {};
    const auto& [part, frame] = index_[i];
    return std::to_string(part) + ":" + parts_[part].dataset->name(frame);
  }
  Result<Sample> Load(std::size_t i) const override {
    if (i >= index_.size())
      return Status::InvalidArgument("frame index " + std::to_string(i) + " out of range");
    const auto& [part, frame] = index_[i];
    return parts_[part].dataset->Load(frame);
  }

 private:
  std::vector<FrameSelection> parts_;
  std::vector<std::pair<std::size_t, int>> index_;
};

}  // namespace

Result<FrameSelection> SelectFrames(const std::vector<DatasetSpec>& specs) {
  if (specs.empty()) return Status::InvalidArgument("no dataset given");
  if (specs.size() == 1) return SelectFrames(specs.front());
  std::vector<FrameSelection> parts;
  std::string formats;
  for (const DatasetSpec& spec : specs) {
    auto part = SelectFrames(spec);
    if (!part.ok()) return part.status();
    formats += (formats.empty() ? "" : "+") + part->format;
    parts.push_back(std::move(*part));
  }
  FrameSelection out;
  out.format = formats;
  for (std::size_t p = 0; p < parts.size(); ++p)
    out.source.insert(out.source.end(), parts[p].frames.size(), static_cast<int>(p));
  out.dataset = std::make_unique<ConcatenatedDataset>(std::move(parts));
  for (int i = 0; i < static_cast<int>(out.dataset->size()); ++i) out.frames.push_back(i);
  return out;
}

}  // namespace tod
