// Options `tod train`, `tod eval` and `tod analyse` share: which frames of which dataset, and
// what an unreadable frame does (DatasetSelection).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "core/datasets/dataset_selection.h"

namespace tod::cli {

// The text --on-bad-frame takes, checked by CLI11; DatasetSelectionFrom parses it.
struct DatasetArgs {
  DatasetSelection data;  // its split: the command's default
  std::string on_bad_frame = "fail";
};

inline DatasetArgs DatasetArgsOfSplit(const std::string& split) {
  return {.data = SelectionOfSplit(split), .on_bad_frame = "fail"};
}

// Adds --data (required), --format, --split, --split-file, --max-frames and, with
// `bad_frames`, --on-bad-frame, writing into `args`.
void AddDatasetOptions(CLI::App* cmd, DatasetArgs& args, bool bad_frames);

// The selection with --on-bad-frame parsed.
DatasetSelection DatasetSelectionFrom(const DatasetArgs& args);

}  // namespace tod::cli
