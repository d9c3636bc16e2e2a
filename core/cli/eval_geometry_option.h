// --geometry, which `tod eval` and `tod cv` share: where the detector's road geometry comes from
// while a split is evaluated (EvalGeometry).
#pragma once

#include <CLI/CLI.hpp>

#include "core/evaluation/evaluator.h"

namespace tod::cli {

// Adds --geometry frame|camera|bundle (default frame), writing into `geometry`.
void AddEvalGeometryOption(CLI::App* cmd, EvalGeometry* geometry);

}  // namespace tod::cli
