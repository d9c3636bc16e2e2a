#include "core/cli/dataset_options.h"

namespace tod::cli {

void AddDatasetOptions(CLI::App* cmd, DatasetArgs& args, bool bad_frames) {
  DatasetSelection& data = args.data;
  cmd->add_option("--data", data.data_root, "dataset root")->required();
  cmd->add_option("--format", data.format, "dataset format (auto detects it from the layout)")
      ->check(CLI::IsMember({"auto", "laf", "masks", "modd2"}))
      ->capture_default_str();
  cmd->add_option("--split", data.split, "split to use")->capture_default_str();
  cmd->add_option("--split-file", data.split_file,
                  "masks format: `train|test <stem>` lines to use instead of DATA/split.txt");
  cmd->add_option("--max-frames", data.max_frames,
                  "at most this many frames, spread over the split (0 = all; fewer for a quick "
                  "run)")
      ->capture_default_str();
  if (!bad_frames) return;
  cmd->add_option("--on-bad-frame", args.on_bad_frame,
                  "fail: stop at an unreadable frame; skip: leave it out, list and count it")
      ->check(CLI::IsMember({"fail", "skip"}))
      ->capture_default_str();
}

DatasetSelection DatasetSelectionFrom(const DatasetArgs& args) {
  DatasetSelection data = args.data;
  data.on_bad_frame = *ParseBadFramePolicy(args.on_bad_frame);  // checked by CLI11
  return data;
}

}  // namespace tod::cli
