// `qvr control`: run a fovea-sizing policy over a workload (placeholder until the controller
// lands in this same change).
#include "commands.h"

namespace qvr::cli {
static Registered registerControl(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("control", "Run a fovea-sizing policy over a workload");
    return {cmd, [] { return 1; }};
}
QVR_REGISTER_COMMAND(30, registerControl);

}  // namespace qvr::cli
