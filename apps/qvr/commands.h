// Subcommand registration for the `qvr` command. Each cmd_<name>.cpp defines a function that
// adds its subcommand to the CLI11 app and returns the action to run, and registers it with
// QVR_REGISTER_COMMAND; main.cpp needs no edit when a part adds a command.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace qvr::cli {

// An action returns the process exit code: 0 on success, 1 on a runtime failure, 2 on bad
// input (malformed options, files or traces), with a message on stderr.
using Action = std::function<int()>;

struct Registered {
    CLI::App* command = nullptr;
    Action action;
};

using RegisterFn = Registered (*)(CLI::App& app);

struct CommandEntry {
    int order;  // help lists commands in this order
    RegisterFn fn;
};

inline std::vector<CommandEntry>& commandRegistry() {
    static std::vector<CommandEntry> registry;
    return registry;
}

inline bool addCommand(int order, RegisterFn fn) {
    commandRegistry().push_back({order, fn});
    return true;
}

}  // namespace qvr::cli

// Use inside namespace qvr::cli, after the register function.
#define QVR_REGISTER_COMMAND(order, fn) \
    [[maybe_unused]] static const bool qvr_registered_##fn = addCommand(order, &fn)
