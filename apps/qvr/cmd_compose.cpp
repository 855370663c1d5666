// `qvr compose`: the display image UCA (paper §4.2, Eq. 3–4) makes from one frame's layers and
// poses, written to PNG so a person can look at it. Layers come from PNG files or, by default,
// from the built-in test pattern.
#if defined(QVR_HAVE_COMPOSE)
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "command_error.h"
#include "commands.h"
#include "qvr/compose/layer_files.h"
#include "qvr/compose/uca.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr::cli {

namespace {

struct ComposeCli {
    std::string profile = "default";
    double e1_deg = 15.0;
    std::string gaze = "0,0";
    std::string render_pose = "0,0,0";
    std::string display_pose = "2,1,0.5";
    std::string layers_dir;
    std::string write_layers_dir;
    std::string out = "qvr-out/compose.png";
    bool two_pass = false;
    bool scalar = false;
};

// "YAW,PITCH,ROLL" in degrees, each finite and within ±180.
bool parsePose(const std::string& text, Pose& pose) {
    double v[3];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3)
        return false;
    for (double x : v)
        if (!std::isfinite(x) || std::fabs(x) > 180.0)
            return false;
    pose.orientation = quatFromEulerDeg({v[0], v[1], v[2]});
    return true;
}

}  // namespace

static Registered registerCompose(CLI::App& app) {
    auto opts = std::make_shared<ComposeCli>();
    CLI::App* cmd = app.add_subcommand(
        "compose", "Compose one frame's layers for a display pose with UCA and write a PNG");
    addProfileOption(cmd, opts->profile);
    addFinite(cmd, "--e1", opts->e1_deg, "Fovea radius e1 in degrees (the layer plan)", 0.0, 180.0);
    addGazePointOption(cmd, opts->gaze);
    const CLI::Validator pose(
        [](std::string& text) -> std::string {
            Pose p;
            return parsePose(text, p)
                       ? std::string()
                       : "must be yaw,pitch,roll in degrees within ±180, got '" + text + "'";
        },
        "YAW,PITCH,ROLL", "POSE");
    cmd->add_option("--render-pose", opts->render_pose,
                    "Yaw,pitch,roll in degrees the layers were rendered for")
        ->check(pose)
        ->capture_default_str();
    cmd->add_option("--display-pose", opts->display_pose,
                    "Yaw,pitch,roll in degrees of the newer display pose")
        ->check(pose)
        ->capture_default_str();
    cmd->add_option("--layers", opts->layers_dir,
                    "Read {left,right}_{fovea,middle,outer}.png from this directory instead of "
                    "rendering the test pattern; sizes must match the plan (see qvr plan)");
    cmd->add_option("--write-layers", opts->write_layers_dir,
                    "Also write the layer images used, in the --layers naming")
        ->check(outputFolder());
    cmd->add_option("--out", opts->out, "Output PNG: left and right eye side by side")
        ->check(writableFileMakingFolder())
        ->capture_default_str();
    cmd->add_flag("--two-pass", opts->two_pass, "Use the two-pass reference instead of UCA");
    cmd->add_flag("--scalar", opts->scalar, "Use the scalar twin of the UCA kernel");
    Action action = [opts]() -> int {
        // Each checked when parsed.
        Gaze gaze;
        Pose render_pose, display_pose;
        parseGazeDeg(opts->gaze, gaze);
        parsePose(opts->render_pose, render_pose);
        parsePose(opts->display_pose, display_pose);
        auto profile = hmdProfileByName(opts->profile);
        if (!profile)
            return fail("compose", profile.error(), 2);
        const LayerPlan plan = LayerPlanner(*profile).plan(gaze, opts->e1_deg);
        auto frame = layerFrameFrom(opts->layers_dir, *profile, plan, render_pose);
        if (!frame)
            return fail("compose", frame.error(), 2);
        if (!opts->write_layers_dir.empty())
            if (Status st = writeLayerPngs(opts->write_layers_dir, *frame); !st)
                return fail("compose", st.error(), 1);
        Compositor compositor(*profile, ComposeOptions{.simd = !opts->scalar});
        std::array<ImageRgba8, 2> out;
        auto report = opts->two_pass ? compositor.composeTwoPass(*frame, display_pose, out)
                                     : compositor.compose(*frame, display_pose, out);
        if (!report)
            return fail("compose", report.error(), 2);
        if (Status st = writeSideBySidePng(opts->out, out); !st)
            return fail("compose", st.error(), 1);
        fmt::print(
            "{} -> {} ({}x{} per eye, left|right; e1 {:.1f} e2 {:.1f} deg; warp {:.2f} "
            "deg; tiles {} empty, {} single, {} border)\n",
            opts->two_pass ? "two-pass" : "UCA", opts->out, profile->width_px, profile->height_px,
            plan.e1_deg, plan.e2_deg, report->warp_deg, report->tiles.empty, report->tiles.single,
            report->tiles.border);
        return 0;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(60, registerCompose);

}  // namespace qvr::cli
#endif
