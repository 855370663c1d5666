// `qvr compose`: the display image UCA (paper §4.2, Eq. 3–4) makes from one frame's layers and
// poses, written to PNG so a person can look at it. Layers come from PNG files or, by default,
// from the built-in test pattern.
#if defined(QVR_HAVE_COMPOSE)
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "commands.h"
#include "options.h"
#include "qvr/compose/layer_files.h"
#include "qvr/compose/test_pattern.h"
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

bool parseNumbers(const std::string& text, double* v, int n, double limit) {
    char tail = 0;
    int got = 0;
    if (n == 2)
        got = std::sscanf(text.c_str(), "%lf,%lf%c", &v[0], &v[1], &tail);
    if (n == 3)
        got = std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail);
    if (got != n)
        return false;
    for (int i = 0; i < n; ++i) {
        if (!std::isfinite(v[i]) || std::fabs(v[i]) > limit)
            return false;
    }
    return true;
}

}  // namespace

static Registered registerCompose(CLI::App& app) {
    auto opts = std::make_shared<ComposeCli>();
    CLI::App* cmd = app.add_subcommand(
        "compose", "Compose one frame's layers for a display pose with UCA and write a PNG");
    addProfileOption(cmd, opts->profile);
    cmd->add_option("--e1", opts->e1_deg, "Fovea radius e1 in degrees (the layer plan)")
        ->check(finiteRange(0.0, 180.0))
        ->capture_default_str();
    addGazePointOption(cmd, opts->gaze);
    const CLI::Validator pose(
        [](std::string& text) -> std::string {
            double v[3];
            return parseNumbers(text, v, 3, 180.0)
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
        double gaze[2], render[3], display[3];
        parseNumbers(opts->gaze, gaze, 2, 80.0);
        parseNumbers(opts->render_pose, render, 3, 180.0);
        parseNumbers(opts->display_pose, display, 3, 180.0);
        auto profile = hmdProfileByName(opts->profile);
        if (!profile) {
            std::fprintf(stderr, "qvr compose: %s\n", profile.error().c_str());
            return 2;
        }
        const LayerPlan plan = LayerPlanner(*profile).plan({gaze[0], gaze[1]}, opts->e1_deg);
        Pose render_pose, display_pose;
        render_pose.orientation = quatFromEulerDeg({render[0], render[1], render[2]});
        display_pose.orientation = quatFromEulerDeg({display[0], display[1], display[2]});
        auto frame =
            opts->layers_dir.empty()
                ? makeTestPatternFrame(*profile, plan, render_pose, 0,
                                       renderTestPattern(profile->width_px, profile->height_px))
                : readLayerPngs(opts->layers_dir, plan, render_pose);
        if (!frame) {
            std::fprintf(stderr, "qvr compose: %s\n", frame.error().c_str());
            return 2;
        }
        if (Status st = validateFrame(*profile, *frame); !st) {
            std::fprintf(stderr, "qvr compose: %s\n", st.error().c_str());
            return 2;
        }
        if (!opts->write_layers_dir.empty()) {
            if (Status st = writeLayerPngs(opts->write_layers_dir, *frame); !st) {
                std::fprintf(stderr, "qvr compose: %s\n", st.error().c_str());
                return 1;
            }
        }
        ComposeOptions copts;
        copts.simd = !opts->scalar;
        Compositor compositor(*profile, copts);
        std::array<ImageRgba8, 2> out;
        auto report = opts->two_pass ? compositor.composeTwoPass(*frame, display_pose, out)
                                     : compositor.compose(*frame, display_pose, out);
        if (!report) {
            std::fprintf(stderr, "qvr compose: %s\n", report.error().c_str());
            return 2;
        }
        if (Status st = writeSideBySidePng(opts->out, out); !st) {
            std::fprintf(stderr, "qvr compose: %s\n", st.error().c_str());
            return 1;
        }
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
