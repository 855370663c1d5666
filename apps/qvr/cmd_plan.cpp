// `qvr plan`: print the layer plan (paper §3.1, Eq. 1) for a gaze point and a fovea radius.
#include <cstdio>
#include <string>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/foveation/layer_plan_report.h"

namespace qvr::cli {

namespace {

struct PlanOptions {
    double e1_deg = 15.0;
    std::string gaze = "0,0";
    std::string profile = "default";
    bool json = false;
};

}  // namespace

static Registered registerPlan(CLI::App& app) {
    auto o = std::make_shared<PlanOptions>();
    CLI::App* cmd = app.add_subcommand("plan", "Print the layer plan (Eq. 1) for a fovea radius");
    addE1Option(cmd, o->e1_deg, 180.0);
    addGazePointOption(cmd, o->gaze);
    addProfileOption(cmd, o->profile);
    addJsonFlag(cmd, o->json);
    Action action = [o]() -> int {
        const HmdProfile profile = checkedHmdProfile(o->profile);
        const LayerPlan plan = LayerPlanner(profile).plan(checkedGaze(o->gaze), o->e1_deg);
        printReport(o->json, layerPlanJson(plan, profile), layerPlanText(plan, profile));
        return 0;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(20, registerPlan);

}  // namespace qvr::cli
