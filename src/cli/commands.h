#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace bdptref::cli {

// Each registers a subcommand; the returned function runs it and gives the exit code.
std::function<int()> addRenderCommand(CLI::App& app);
std::function<int()> addInfoCommand(CLI::App& app);

}  // namespace bdptref::cli
