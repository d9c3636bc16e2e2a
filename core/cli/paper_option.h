// `--paper NAME` (repeatable), shared by `tod train` and `tod cv`: one switch per adopted
// deviation back to the paper's behaviour (core/training/paper_switches.h).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/training/train_options.h"

namespace tod::cli {

// Adds --paper, checked against the switches' names, collecting them into `names`.
void AddPaperOption(CLI::App* cmd, std::vector<std::string>& names);

// `options` with every switch of `names` (as AddPaperOption checked them) applied.
void ApplyPaperSwitches(const std::vector<std::string>& names, TrainOptions& options);

}  // namespace tod::cli
