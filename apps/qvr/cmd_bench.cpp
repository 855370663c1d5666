// `qvr bench <name>`: the headline measurements of each part, printed as text or JSON. The
// benchmarks themselves register from their own cmd_bench_<name>.cpp (bench_commands.h).
#include <algorithm>
#include <memory>
#include <vector>

#include "bench_commands.h"
#include "commands.h"

namespace qvr::cli {

static Registered registerBench(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("bench", "Run a headline benchmark (see qvr bench --help)");
    cmd->require_subcommand(1);
    auto entries = benchRegistry();
    std::sort(entries.begin(), entries.end(),
              [](const auto& a, const auto& b) { return a.order < b.order; });
    auto benches = std::make_shared<std::vector<Registered>>();
    for (const auto& e : entries)
        benches->push_back(e.fn(*cmd));
    Action action = [benches]() -> int {
        for (auto& b : *benches) {
            if (b.command->parsed())
                return b.action();
        }
        return 2;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(80, registerBench);

}  // namespace qvr::cli
