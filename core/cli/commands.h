// The `tod` command-line tool: one subcommand a file; each registers its options on the app
// and runs when selected. Exit codes: 0 ok, 1 failure (message on stderr), 2 usage.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace tod::cli {

// Adds a subcommand; the returned function runs it after parsing and yields the exit code.
using Runner = std::function<int()>;
Runner AddSynthCommand(CLI::App& app);
Runner AddTrainCommand(CLI::App& app);
Runner AddDetectCommand(CLI::App& app);
Runner AddEvalCommand(CLI::App& app);
Runner AddAnalyseCommand(CLI::App& app);
Runner AddBenchCommand(CLI::App& app);
Runner AddCvCommand(CLI::App& app);
Runner AddHorizonCommand(CLI::App& app);
Runner AddCalibrateCommand(CLI::App& app);
Runner AddReframeCommand(CLI::App& app);

// Prints "tod: <message>" to stderr and returns 1.
int Fail(const std::string& message);

// Makes `--threads N` (N > 0) bound OpenCV's own loops too. Without it OpenCV's TBB backend
// hands parts of its filters to a worker thread whatever the option says, so `--threads 1` was
// not one thread: which thread allocated which buffer then depended on the machine's load, and
// the trainer's peak RSS on the same frames varied by up to 11 MB (84-95 MB on a busy machine).
void BoundOpenCvThreads(int threads);

}  // namespace tod::cli
