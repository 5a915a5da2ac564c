#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace mfr::cli {

/// Each command registers its subcommand and returns the function that runs it (exit code).
using Runner = std::function<int()>;
Runner addRenderCommand(CLI::App& app);
Runner addInfoCommand(CLI::App& app);
Runner addMetricsCommand(CLI::App& app);
Runner addCompareCommand(CLI::App& app);
Runner addDatasetCommand(CLI::App& app);
Runner addTrainCommand(CLI::App& app);
Runner addPresetsCommand(CLI::App& app);
/// mfr view (built with the GL engine: MFR_BUILD_GL).
Runner addViewCommand(CLI::App& app);

}  // namespace mfr::cli
