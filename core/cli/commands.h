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

// Prints "tod: <message>" to stderr and returns 1.
int Fail(const std::string& message);

}  // namespace tod::cli
