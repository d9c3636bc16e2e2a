// tod reframe --data DIR --out DIR [--scale S] [--crop WxH] [--shift-up F]
//             [--format png|jpg|webp] [--quality Q]
// Makes a labelled dataset (masks layout: images/, labels_masks/) into another camera's frames
// (core/data/reframe.h): scaled, centre-cropped, shifted, re-encoded. The self-calibration is
// measured on them: `tod eval --geometry camera` on the output against the unmodified frames.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/data/reframe.h"

namespace tod::cli {
namespace {

namespace fs = std::filesystem;

bool IsImage(const fs::path& p) {
  const std::string e = p.extension().string();
  return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".webp";
}

Status WriteEncoded(const fs::path& path, const cv::Mat& image, const std::vector<int>& flags) {
  std::vector<uchar> bytes;
  if (!cv::imencode(path.extension().string(), image, bytes, flags))
    return Status::Internal("cannot encode " + path.string());
  return WriteFileAtomically(path.string(), std::string(bytes.begin(), bytes.end()));
}

std::vector<int> EncodeFlags(const std::string& format, int quality) {
  if (format == "jpg") return {cv::IMWRITE_JPEG_QUALITY, quality};
  if (format == "webp") return {cv::IMWRITE_WEBP_QUALITY, quality};
  return {};
}

// One frame and its mask reframed into `out`; the mask stays PNG (labels are not compressed).
Status ReframeOne(const fs::path& image_path, const fs::path& mask_dir, const fs::path& out,
                  const ReframeParams& params, const std::string& format, int quality) {
  const std::string stem = image_path.stem().string();
  const cv::Mat image = cv::imread(image_path.string(), cv::IMREAD_COLOR);
  // The masks layout's two mask names (masks_reader.cc); the output uses the first.
  cv::Mat mask = cv::imread((mask_dir / (stem + ".png")).string(), cv::IMREAD_UNCHANGED);
  if (mask.empty())
    mask = cv::imread((mask_dir / (stem + "_labels_semantic.png")).string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) return Status::InvalidArgument("cannot read " + image_path.string());
  if (mask.empty() || mask.size() != image.size())
    return Status::InvalidArgument("no mask of the frame's size for " + image_path.string());
  const cv::Mat moved = Reframe(image, params, ReframeKind::kImage);
  const cv::Mat moved_mask = Reframe(mask, params, ReframeKind::kLabels);
  if (moved.empty())
    return Status::InvalidArgument("--crop is larger than the scaled frame of " +
                                   image_path.string());
  if (Status st =
          WriteEncoded(out / "images" / (stem + "." + format), moved, EncodeFlags(format, quality));
      !st.ok())
    return st;
  return WriteEncoded(out / "labels_masks" / (stem + ".png"), moved_mask, {});
}

}  // namespace

Runner AddReframeCommand(CLI::App& app) {
  struct Args {
    std::string data, out, crop, format = "png";
    ReframeParams params;
    int quality = 90;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "reframe", "make a labelled dataset (masks layout) into another camera's frames");
  cmd->add_option("--data", args->data, "dataset root (images/, labels_masks/)")->required();
  cmd->add_option("--out", args->out, "output dataset root (same layout)")->required();
  cmd->add_option("--scale", args->params.scale, "resize factor, first")
      ->check(CLI::Range(0.1, 4.0))
      ->capture_default_str();
  cmd->add_option("--crop", args->crop, "centre crop WxH after scaling (e.g. 1920x1080)");
  cmd->add_option("--shift-up", args->params.shift_up,
                  "move the picture up by this share of its height (negative: down)")
      ->check(CLI::Range(-0.5, 0.5))
      ->capture_default_str();
  cmd->add_option("--format", args->format, "image encoding")
      ->check(CLI::IsMember({"png", "jpg", "webp"}))
      ->capture_default_str();
  cmd->add_option("--quality", args->quality, "JPEG / WebP quality (WebP: over 100 lossless)")
      ->check(CLI::Range(1, 101))
      ->capture_default_str();
  return [args] {
    ReframeParams params = args->params;
    if (!args->crop.empty() &&
        std::sscanf(args->crop.c_str(), "%dx%d", &params.crop.width, &params.crop.height) != 2)
      return Fail("--crop: expected WxH, got '" + args->crop + "'");
    const fs::path data(args->data), out(args->out);
    std::vector<fs::path> images;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(data / "images", ec))
      if (IsImage(entry.path())) images.push_back(entry.path());
    if (ec || images.empty()) return Fail("no images under " + (data / "images").string());
    std::sort(images.begin(), images.end());
    fs::create_directories(out / "images", ec);
    fs::create_directories(out / "labels_masks", ec);
    if (ec) return Fail("cannot create " + out.string() + ": " + ec.message());
    for (const fs::path& image : images) {
      const Status st =
          ReframeOne(image, data / "labels_masks", out, params, args->format, args->quality);
      if (!st.ok()) return Fail(st.message());
    }
    // The frames keep their names, so the dataset's splits still hold.
    std::error_code no_split;
    if (fs::is_regular_file(data / "split.txt", no_split)) {
      fs::copy_file(data / "split.txt", out / "split.txt", fs::copy_options::overwrite_existing,
                    ec);
      if (ec) return Fail("cannot copy split.txt: " + ec.message());
    }
    std::printf("reframed %zu frames into %s\n", images.size(), out.c_str());
    return 0;
  };
}

}  // namespace tod::cli
