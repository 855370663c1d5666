// `qvr bench <name>`: the headline measurements of each part, printed as text or JSON. The
// benchmarks themselves register from their own cmd_bench_<name>.cpp (bench_commands.h).
#include "bench_commands.h"

namespace qvr::cli {

static Registered registerBench(CLI::App& app) {
    return mountSubcommands(app, "bench", "Run a headline benchmark (see qvr bench --help)");
}

QVR_REGISTER_COMMAND(80, registerBench);

}  // namespace qvr::cli
