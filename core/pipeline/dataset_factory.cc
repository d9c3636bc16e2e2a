#include "core/pipeline/dataset_factory.h"

#include <algorithm>

#include "core/data/laf_reader.h"
#include "core/modd2/modd2_reader.h"

namespace tod {

Result<std::string> DetectDatasetFormat(const std::string& root) {
  if (LooksLikeLaf(root)) return std::string("laf");
  if (LooksLikeModd2(root)) return std::string("modd2");
  return Status::NotFound(root +
                          ": neither the Lost and Found layout (leftImg8bit/, gtCoarse/) nor the "
                          "MODDv2 layout (video_data/, annotationsV2/); use --format");
}

Result<std::unique_ptr<Dataset>> OpenDataset(const std::string& root, const std::string& split,
                                             const std::string& format) {
  std::string chosen = format;
  if (chosen == "auto") {
    auto detected = DetectDatasetFormat(root);
    if (!detected.ok()) return detected.status();
    chosen = *detected;
  }
  if (chosen == "laf") return OpenLafDataset(root, split);
  if (chosen == "modd2") return OpenModd2Dataset(root, split);
  return Status::InvalidArgument("unknown dataset format '" + format + "' (auto, laf, modd2)");
}

std::vector<int> SpreadIndices(int total, int count) {
  const long long n = count > 0 ? std::min(total, count) : total;
  std::vector<int> out;
  for (long long j = 0; j < n; ++j) out.push_back(static_cast<int>(j * total / n));
  return out;
}

Result<FrameSelection> SelectFrames(const std::string& root, const std::string& split,
                                    const std::string& format, int max_frames) {
  FrameSelection out;
  out.format = format;
  if (out.format == "auto") {
    auto detected = DetectDatasetFormat(root);
    if (!detected.ok()) return detected.status();
    out.format = *detected;
  }
  auto dataset = OpenDataset(root, split, out.format);
  if (!dataset.ok()) return dataset.status();
  out.dataset = std::move(*dataset);
  const int total = static_cast<int>(out.dataset->size());
  if (total == 0) return Status::InvalidArgument(root + ": the " + split + " split is empty");
  out.frames = SpreadIndices(total, max_frames);
  return out;
}

}  // namespace tod
