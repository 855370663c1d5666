// `qvr bench render`: milliseconds per layer and triangles per second of the OpenGL renderer
// (paper §3.2), per scene (experiment/render_bench.h).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bench_commands.h"
#include "cli_parse.h"
#include "qvr/experiment/render_bench.h"

namespace qvr::cli {

namespace {

struct RenderBenchOptions {
    std::vector<std::string> scenes;
    std::string profile = "default";
    std::string gaze = "0,0";
    bool json = false;
    experiment::RenderBenchPlan plan;
};

int runRenderBench(const RenderBenchOptions& o) {
    constexpr const char* kCmd = "qvr bench render";
    std::vector<std::string> names = o.scenes;
    if (names.empty()) {
        names = experiment::defaultRenderBenchScenes();
        if (names.size() == 1 && !o.json)
            std::printf("(OpenArena not installed: benchmarking builtin:room only)\n");
    }
    std::vector<experiment::BenchScene> scenes;
    for (const std::string& name : names) {
        auto scene = experiment::loadBenchScene(name);
        if (!scene) {
            std::fprintf(stderr, "%s: %s\n", kCmd, scene.error().c_str());
            return 2;
        }
        scenes.push_back(std::move(*scene));
    }
    experiment::RenderBenchPlan plan = o.plan;
    plan.profile = checkedHmdProfile(o.profile);
    plan.gaze = checkedGaze(o.gaze);
    auto result = experiment::runRenderBench(plan, scenes);
    if (!result) {
        std::fprintf(stderr, "%s: %s\n", kCmd, result.error().c_str());
        return 1;
    }
    printReport(o.json, experiment::renderBenchJson(*result), experiment::renderBenchText(*result));
    return 0;
}

}  // namespace

static Registered registerRenderBench(CLI::App& bench) {
    auto o = std::make_shared<RenderBenchOptions>();
    CLI::App* cmd = bench.add_subcommand(
        "render", "OpenGL renderer: ms per layer and triangles per second (paper §3.2)");
    cmd->add_option("--scene", o->scenes,
                    "Scene(s) to render (default: builtin:room, and openarena:oa_dm5 when "
                    "installed)");
    addProfileOption(cmd, o->profile);
    addE1Option(cmd, o->plan.e1_deg, 90.0);
    addGazePointOption(cmd, o->gaze);
    addFramesOption(cmd, o->plan.frames, 1, 10000, "Timed frames per scene (median reported)");
    addLodOption(cmd, o->plan.renderer.lod_error_px);
    addMsaaOption(cmd, o->plan.renderer.msaa_samples);
    addJsonFlag(cmd, o->json);
    return {cmd, [o]() { return runRenderBench(*o); }};
}

QVR_REGISTER_BENCH(20, registerRenderBench);

}  // namespace qvr::cli
