// `qvr compose`: the display image UCA (paper §4.2, Eq. 3–4) makes from one frame's layers and
// poses, written to PNG so a person can look at it. Layers come from PNG files or, by default,
// from the built-in test pattern.
#if defined(QVR_HAVE_COMPOSE)
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "commands.h"
#include "options.h"
#include "qvr/compose/png_io.h"
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

const char* kEyeNames[2] = {"left", "right"};
const char* kLayerNames[3] = {"fovea", "middle", "outer"};

ImageRgba8& layerOf(EyeLayerImages& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}
const LayerRect& rectOf(const EyeLayers& e, int k) {
    return k == 0 ? e.fovea : (k == 1 ? e.middle : e.outer);
}

std::string layerPath(const std::string& dir, int eye, int k) {
    return (std::filesystem::path(dir) / fmt::format("{}_{}.png", kEyeNames[eye], kLayerNames[k]))
        .string();
}

ImageRgba8 sideBySide(const std::array<ImageRgba8, 2>& eyes) {
    ImageRgba8 out(eyes[0].width() * 2, eyes[0].height());
    for (int y = 0; y < out.height(); ++y) {
        for (int eye = 0; eye < 2; ++eye) {
            const uint8_t* src = eyes[static_cast<size_t>(eye)].row(y);
            std::copy(src, src + eyes[0].strideElems(), out.row(y) + eye * eyes[0].strideElems());
        }
    }
    return out;
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
        LayerFrame frame;
        if (opts->layers_dir.empty()) {
            frame = makeTestPatternFrame(*profile, plan, render_pose, 0,
                                         renderTestPattern(profile->width_px, profile->height_px));
        } else {
            frame.plan = plan;
            frame.render_pose = render_pose;
            for (int eye = 0; eye < 2; ++eye) {
                for (int k = 0; k < 3; ++k) {
                    if (rectOf(plan.eyes[static_cast<size_t>(eye)], k).empty())
                        continue;
                    auto img = readPng(layerPath(opts->layers_dir, eye, k));
                    if (!img) {
                        std::fprintf(stderr, "qvr compose: %s\n", img.error().c_str());
                        return 2;
                    }
                    layerOf(frame.eyes[static_cast<size_t>(eye)], k) = std::move(*img);
                }
            }
        }
        if (Status st = validateFrame(*profile, frame); !st) {
            std::fprintf(stderr, "qvr compose: %s\n", st.error().c_str());
            return 2;
        }
        if (!opts->write_layers_dir.empty()) {
            std::error_code ec;
            std::filesystem::create_directories(opts->write_layers_dir, ec);
            for (int eye = 0; eye < 2; ++eye) {
                for (int k = 0; k < 3; ++k) {
                    const ImageRgba8& img = layerOf(frame.eyes[static_cast<size_t>(eye)], k);
                    if (img.empty())
                        continue;
                    if (Status st = writePng(layerPath(opts->write_layers_dir, eye, k), img); !st) {
                        std::fprintf(stderr, "qvr compose: %s\n", st.error().c_str());
                        return 1;
                    }
                }
            }
        }
        ComposeOptions copts;
        copts.simd = !opts->scalar;
        Compositor compositor(*profile, copts);
        std::array<ImageRgba8, 2> out;
        auto report = opts->two_pass ? compositor.composeTwoPass(frame, display_pose, out)
                                     : compositor.compose(frame, display_pose, out);
        if (!report) {
            std::fprintf(stderr, "qvr compose: %s\n", report.error().c_str());
            return 2;
        }
        const std::filesystem::path out_path(opts->out);
        if (out_path.has_parent_path()) {
            std::error_code ec;
            std::filesystem::create_directories(out_path.parent_path(), ec);
        }
        if (Status st = writePng(opts->out, sideBySide(out)); !st) {
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
