// Commands made of sub-commands (`qvr bench`, `qvr trace`): each sub-command lives in its own
// cmd_<group>_<name>.cpp and registers under its group; the group's command mounts them all.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"

namespace qvr::cli {

struct SubcommandEntry {
    std::string group;
    CommandEntry entry;  // help lists a group's sub-commands in their order
};

inline std::vector<SubcommandEntry>& subcommandRegistry() {
    static std::vector<SubcommandEntry> registry;
    return registry;
}

inline bool addSubcommand(const char* group, int order, RegisterFn fn) {
    subcommandRegistry().push_back({group, {order, fn}});
    return true;
}

// Adds `name` with every sub-command registered under it; its action runs the one given.
inline Registered mountSubcommands(CLI::App& app, const std::string& name,
                                   const std::string& help) {
    CLI::App* cmd = app.add_subcommand(name, help)->require_subcommand(1);
    auto entries = subcommandRegistry();
    std::stable_sort(entries.begin(), entries.end(),
                     [](const auto& a, const auto& b) { return a.entry.order < b.entry.order; });
    auto subs = std::make_shared<std::vector<Registered>>();
    for (const auto& e : entries)
        if (e.group == name)
            subs->push_back(e.entry.fn(*cmd));
    return {cmd, [subs]() -> int {
                for (auto& s : *subs)
                    if (s.command->parsed())
                        return s.action();
                return 2;
            }};
}

}  // namespace qvr::cli

// Use inside namespace qvr::cli, after the register function.
#define QVR_REGISTER_SUBCOMMAND(group, order, fn) \
    [[maybe_unused]] static const bool qvr_sub_registered_##fn = addSubcommand(group, order, &fn)
#define QVR_REGISTER_BENCH(order, fn) QVR_REGISTER_SUBCOMMAND("bench", order, fn)
