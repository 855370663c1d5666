// qvr: collaborative foveated rendering for mobile VR (Q-VR, ASPLOS '21) — one command with
// subcommands. Start-up parsing may throw; main turns every failure into a message and a
// non-zero exit (STYLE.md §5).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <vector>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "commands.h"

int main(int argc, char** argv) {
    CLI::App app{
        "qvr — collaborative foveated rendering for mobile VR (Q-VR, ASPLOS '21).\n"
        "The headset renders the fovea, a server renders the periphery at the resolution human\n"
        "acuity allows, and a learned controller (LIWC) sizes the fovea every frame."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "qvr 0.1.0");
    auto entries = qvr::cli::commandRegistry();
    std::sort(entries.begin(), entries.end(),
              [](const auto& a, const auto& b) { return a.order < b.order; });
    std::vector<qvr::cli::Registered> commands;
    for (const auto& e : entries)
        commands.push_back(e.fn(app));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    try {
        for (auto& c : commands) {
            if (c.command->parsed())
                return c.action();
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "qvr: error: %s\n", e.what());
        return 1;
    }
    return 2;
}
