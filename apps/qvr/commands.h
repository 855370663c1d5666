// Subcommand registration for the `qvr` command: each cmd_<name>.cpp defines one register
// function that adds its subcommand and options to the CLI11 app and returns the action to run.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace qvr::cli {

// An action returns the process exit code. Bad input is reported on stderr with exit code 2;
// runtime failures with 1.
using Action = std::function<int()>;

struct Registered {
    CLI::App* command = nullptr;
    Action action;
};

Registered registerPlan(CLI::App& app);
Registered registerControl(CLI::App& app);

}  // namespace qvr::cli
