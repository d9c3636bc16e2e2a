// tod horizon --data DIR [--split test] [--json FILE]   |   tod horizon IMAGE...
// The horizon the detector's self-calibration estimates on each frame (issue 48), and, where
// the frames are synthetic (tod synth writes each frame's true camera), its error in rows per
// frame and per camera: the running median over the frames sent so far, as the server keeps it,
// against the median true horizon of those frames.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/base/atomic_file.h"
#include "core/calibration/camera_horizon.h"
#include "core/calibration/horizon_estimator.h"
#include "core/cli/commands.h"
#include "core/cli/dataset_options.h"
#include "core/datasets/dataset_factory.h"
#include "core/synth/synth.h"

namespace tod::cli {
namespace {

struct FrameHorizon {
  std::string name;
  int height = 0;
  HorizonEstimate estimate;
  std::optional<double> truth;   // synthetic frames: the camera's true horizon row
  std::optional<double> camera;  // running median of the frames so far, this one included
  // The camera's true horizon over the same frames: the running median of their true rows (a
  // synthetic camera's pitch jitters from frame to frame; its mounting is the median).
  std::optional<double> camera_truth;
};

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::floor(q * static_cast<double>(v.size() - 1) + 0.5))];
}

// Errors at 1024 rows, so frames of any height compare with the targets.
double RowsAt1024(double rows, int height) { return rows * 1024.0 / std::max(1, height); }

nlohmann::json Summary(const std::vector<FrameHorizon>& frames, int camera_after) {
  std::vector<double> found_rows, frame_errors, camera_errors, truths;
  int found = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FrameHorizon& f = frames[i];
    if (f.truth) truths.push_back(*f.truth);
    if (!f.estimate.found) continue;
    ++found;
    found_rows.push_back(RowsAt1024(f.estimate.row, f.height));
    if (f.truth) frame_errors.push_back(RowsAt1024(std::abs(f.estimate.row - *f.truth), f.height));
    if (f.camera_truth && f.camera && static_cast<int>(i) + 1 >= camera_after)
      camera_errors.push_back(RowsAt1024(std::abs(*f.camera - *f.camera_truth), f.height));
  }
  nlohmann::json s = {{"frames", frames.size()},
                      {"found", found},
                      {"found_share", frames.empty() ? 0.0 : double(found) / frames.size()}};
  if (!found_rows.empty()) {
    const double median = Median(found_rows);
    std::vector<double> deviation;
    for (double r : found_rows) deviation.push_back(std::abs(r - median));
    s["median_row_at_1024"] = median;
    s["median_abs_deviation_at_1024"] = Median(deviation);
  }
  if (!frame_errors.empty()) {
    s["frame_error_median"] = Median(frame_errors);
    s["frame_error_p90"] = Quantile(frame_errors, 0.9);
  }
  if (!camera_errors.empty()) {
    s["camera_after_frames"] = camera_after;
    s["camera_error_median"] = Median(camera_errors);
    s["camera_error_max"] = *std::max_element(camera_errors.begin(), camera_errors.end());
  }
  return s;
}

}  // namespace

Runner AddHorizonCommand(CLI::App& app) {
  struct Args {
    DatasetArgs data = DatasetArgsOfSplit("test");
    std::vector<std::string> images;
    std::string json;
    int camera_after = 20;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("horizon",
                         "the horizon row self-calibration estimates per frame, and its error on "
                         "synthetic frames");
  cmd->add_option("--data", args->data.data.data_root, "dataset root (or give IMAGE files)");
  cmd->add_option("--format", args->data.data.format, "auto | laf | masks | modd2");
  cmd->add_option("--split", args->data.data.split, "split of --data (test)");
  cmd->add_option("--max-frames", args->data.data.max_frames, "at most this many frames");
  cmd->add_option("images", args->images, "image files (instead of --data)");
  cmd->add_option("--camera-after", args->camera_after,
                  "frames after which the camera's running median is scored (20)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", args->json, "write every frame's estimate and the summary here");
  return [args] {
    std::vector<FrameHorizon> frames;
    CameraHorizon camera, camera_truth;
    const auto add = [&](const std::string& name, const cv::Mat3b& image,
                         std::optional<double> truth) {
      FrameHorizon f{name, image.rows, EstimateHorizon(image), truth, std::nullopt, std::nullopt};
      if (f.estimate.found) camera.Add(f.estimate.row);
      if (truth) camera_truth.Add(*truth);
      f.camera = camera.Estimate();
      f.camera_truth = camera_truth.Estimate();
      frames.push_back(std::move(f));
    };
    if (!args->data.data.data_root.empty()) {
      auto dataset = OpenDataset(args->data.data.Spec());
      if (!dataset.ok()) return Fail(dataset.status().message());
      for (std::size_t i = 0; i < (*dataset)->size(); ++i) {
        auto sample = (*dataset)->Load(i);
        if (!sample.ok()) return Fail(sample.status().message());
        std::optional<double> truth;
        if (auto cam = ReadSynthCamera(sample->image_path)) truth = cam->horizon_row;
        add(sample->name, sample->image, truth);
      }
    }
    for (const std::string& path : args->images) {
      const cv::Mat3b image = cv::imread(path, cv::IMREAD_COLOR);
      if (image.empty()) return Fail("cannot read image " + path);
      add(path, image, std::nullopt);
    }
    if (frames.empty()) return Fail("no frames: give --data DIR or IMAGE files");
    nlohmann::json per_frame = nlohmann::json::array();
    std::printf("%-40s %6s %9s %9s %7s %6s\n", "frame", "found", "row", "truth", "error", "share");
    for (const FrameHorizon& f : frames) {
      const double err = f.truth && f.estimate.found ? f.estimate.row - *f.truth : NAN;
      std::printf("%-40s %6s %9.1f %9.1f %7.1f %6.3f\n", f.name.c_str(),
                  f.estimate.found ? "yes" : "no", f.estimate.row, f.truth.value_or(NAN), err,
                  f.estimate.peak_share);
      nlohmann::json j = {{"frame", f.name},
                          {"height", f.height},
                          {"found", f.estimate.found},
                          {"row", f.estimate.row},
                          {"peak_share", f.estimate.peak_share},
                          {"segments", f.estimate.segments},
                          {"peak_pairs", f.estimate.peak_pairs}};
      if (!f.estimate.found) j["reason"] = f.estimate.reason;
      if (f.truth) j["truth"] = *f.truth;
      if (f.camera) j["camera"] = *f.camera;
      if (f.camera_truth) j["camera_truth"] = *f.camera_truth;
      per_frame.push_back(j);
    }
    const nlohmann::json summary = Summary(frames, args->camera_after);
    std::cout << summary.dump(1) << "\n";
    if (!args->json.empty()) {
      const Status st = WriteFileAtomically(
          args->json, nlohmann::json{{"frames", per_frame}, {"summary", summary}}.dump(1) + "\n");
      if (!st.ok()) return Fail(st.message());
    }
    return 0;
  };
}

}  // namespace tod::cli
