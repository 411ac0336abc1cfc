#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace bdptref::cli {

// Each registers a subcommand; the returned function runs it and gives the exit code.
std::function<int()> addRenderCommand(CLI::App& app);
std::function<int()> addInfoCommand(CLI::App& app);
std::function<int()> addCompareCommand(CLI::App& app);  // cmd_compare.cpp
std::function<int()> addTraceCommand(CLI::App& app);    // cmd_trace.cpp
std::function<int()> addMisCommand(CLI::App& app);      // cmd_mis.cpp
std::function<int()> addMergeCommand(CLI::App& app);    // cmd_merge.cpp
std::function<int()> addValidateCommand(CLI::App& app); // cmd_validate.cpp
std::function<int()> addDiagnoseCommand(CLI::App& app); // cmd_diagnose.cpp

}  // namespace bdptref::cli
