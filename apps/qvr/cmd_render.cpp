// `qvr render SCENE`: render one frame's layers (paper §3.2) — fovea, middle and outer per eye,
// each at its own resolution — and a full-frame reference per eye, as PNGs a person can look at.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/compose/png_io.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/scene/scene_loader.h"

namespace qvr::cli {

namespace {

struct RenderOptions {
    std::string scene;
    std::string pose;
    int spawn = -1;
    std::string gaze = "0,0";
    double e1_deg = 15.0;
    std::string profile = "default";
    double ipd_mm = 64.0;
    double lightmap_gain = 1.0;
    int msaa = 1;
    float lod_px = 0.0f;
    std::string out_dir;
    bool json = false;
};

// "yaw,pitch,roll,x,y,z": degrees, then metres.
bool parsePose(const std::string& text, Pose& pose) {
    double v[6];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &v[3], &v[4],
                    &v[5], &tail) != 6)
        return false;
    for (double x : v) {
        if (!std::isfinite(x) || std::fabs(x) > 1e5)
            return false;
    }
    pose.orientation = quatFromEulerDeg({v[0], v[1], v[2]});
    pose.position_m = {static_cast<float>(v[3]), static_cast<float>(v[4]),
                       static_cast<float>(v[5])};
    return true;
}

int run(const RenderOptions& o) {
    constexpr const char* kCmd = "qvr render";
    // Gaze and pose are checked when parsed.
    Gaze gaze;
    parseGazeDeg(o.gaze, gaze);
    Pose head;
    if (!o.pose.empty())
        parsePose(o.pose, head);
    auto profile = hmdProfileByName(o.profile);
    if (!profile) {
        std::fprintf(stderr, "%s: %s\n", kCmd, profile.error().c_str());
        return 2;
    }
    auto scene = loadScene(o.scene);
    if (!scene) {
        std::fprintf(stderr, "%s: %s\n", kCmd, scene.error().c_str());
        return 2;
    }
    std::string pose_source = o.pose.empty() ? "origin" : "--pose";
    if (o.pose.empty()) {
        // Stand where a player would: the requested spawn point, else the first one.
        const int spawn = o.spawn >= 0 ? o.spawn : 0;
        if (o.spawn >= static_cast<int>(scene->spawns.size())) {
            std::fprintf(stderr, "%s: --spawn %d, but %s has %zu spawn points\n", kCmd, o.spawn,
                         scene->name.c_str(), scene->spawns.size());
            return 2;
        }
        if (!scene->spawns.empty()) {
            head = poseFromSpawn(scene->spawns[static_cast<size_t>(spawn)]);
            pose_source = fmt::format("spawn {}", spawn);
        }
    }

    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) {
        std::fprintf(stderr, "%s: cannot create --out directory '%s': %s\n", kCmd,
                     o.out_dir.c_str(), ec.message().c_str());
        return 1;
    }

    GlRendererOptions gl_options;
    gl_options.lightmap_gain = static_cast<float>(o.lightmap_gain);
    gl_options.msaa_samples = o.msaa;
    gl_options.lod_error_px = o.lod_px;
    auto renderer = GlRenderer::create(gl_options);
    if (!renderer) {
        std::fprintf(stderr, "%s: %s\n", kCmd, renderer.error().c_str());
        return 1;
    }
    GlRenderer& gl = **renderer;
    if (Status s = gl.upload(*scene); !s) {
        std::fprintf(stderr, "%s: %s\n", kCmd, s.error().c_str());
        return 1;
    }

    const LayerPlan plan = LayerPlanner(*profile).plan(gaze, o.e1_deg);
    CameraOptions camera;
    camera.ipd_m = o.ipd_mm * 1e-3;
    const EulerDeg euler = eulerDegFromQuat(head.orientation);
    if (!o.json) {
        fmt::print("{}: {} triangles; {} ({}x{} per eye); renderer {}\n", scene->name,
                   scene->triangleCount(), profile->name, profile->width_px, profile->height_px,
                   gl.name());
        fmt::print(
            "head at ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.1f} pitch {:.1f} roll {:.1f} deg "
            "({}); gaze ({:.1f}, {:.1f}) deg\n",
            head.position_m.x, head.position_m.y, head.position_m.z, euler.yaw_deg, euler.pitch_deg,
            euler.roll_deg, pose_source, gaze.x_deg, gaze.y_deg);
        fmt::print("e1 {:.2f}  e2* {:.2f}  s1 {:.2f}  s2 {:.2f}\n", plan.e1_deg, plan.e2_deg,
                   plan.s1, plan.s2);
    }

    nlohmann::json j;
    j["scene"] = scene->name;
    j["profile"] = profile->name;
    j["renderer"] = gl.name();
    j["e1_deg"] = plan.e1_deg;
    j["e2_deg"] = plan.e2_deg;
    j["s1"] = plan.s1;
    j["s2"] = plan.s2;
    j["layers"] = nlohmann::json::array();
    ImageRgba8 image;
    auto emit = [&](Eye eye, const char* layer, const LayerRect& rect, const RenderView& view,
                    int& exit_code) {
        auto stats = gl.render(view, image);
        if (!stats) {
            std::fprintf(stderr, "%s: %s %s: %s\n", kCmd, eyeName(eye), layer,
                         stats.error().c_str());
            exit_code = 1;
            return;
        }
        const std::string path =
            (std::filesystem::path(o.out_dir) / fmt::format("{}_{}.png", eyeName(eye), layer))
                .string();
        if (Status s = writePng(path, image); !s) {
            std::fprintf(stderr, "%s: %s\n", kCmd, s.error().c_str());
            exit_code = 1;
            return;
        }
        j["layers"].push_back({{"eye", eyeName(eye)},
                               {"layer", layer},
                               {"rect", {rect.rect.x0, rect.rect.y0, rect.rect.x1, rect.rect.y1}},
                               {"scale", rect.scale},
                               {"width_px", view.width_px},
                               {"height_px", view.height_px},
                               {"gpu_ms", stats->gpu_ms},
                               {"render_ms", stats->render_ms},
                               {"primitives", stats->primitives_generated},
                               {"file", path}});
        if (!o.json)
            fmt::print(
                "  {:<5} {:<6} [{:4},{:4})x[{:4},{:4}) scale {:5.2f} {:5}x{:<5} "
                "{:7.2f} ms {:8} tris  {}\n",
                eyeName(eye), layer, rect.rect.x0, rect.rect.x1, rect.rect.y0, rect.rect.y1,
                rect.scale, view.width_px, view.height_px, stats->render_ms,
                stats->primitives_generated, path);
    };
    int exit_code = 0;
    for (Eye eye : {Eye::kLeft, Eye::kRight}) {
        for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter}) {
            const LayerRect& rect = layerOf(plan.eyes[static_cast<size_t>(eye)], kind);
            if (rect.empty()) {
                if (!o.json)
                    fmt::print("  {:<5} {:<6} empty at this e1, no file\n", eyeName(eye),
                               layerName(kind));
                continue;
            }
            emit(eye, layerName(kind), rect, layerView(*profile, head, eye, rect, camera),
                 exit_code);
        }
        LayerRect full;
        full.rect = {0, 0, profile->width_px, profile->height_px};
        full.width_px = profile->width_px;
        full.height_px = profile->height_px;
        emit(eye, "full", full, fullFrameView(*profile, head, eye, camera), exit_code);
        if (exit_code != 0)
            return exit_code;
    }
    if (o.json)
        std::printf("%s\n", j.dump(2).c_str());
    return 0;
}

}  // namespace

static Registered registerRender(CLI::App& app) {
    auto opts = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render", "Render a frame's fovea/middle/outer layers and full frames per eye to PNG");
    cmd->add_option("SCENE", opts->scene,
                    "openarena:MAP, nexuiz:MAP, builtin:room[?objects=N], or a "
                    ".bsp/.pk3/.gltf/.glb/.obj file")
        ->required();
    auto* pose = cmd->add_option("--pose", opts->pose,
                                 "Head pose yaw,pitch,roll,x,y,z (degrees, metres; y up, -z "
                                 "forward)")
                     ->check(CLI::Validator(
                         [](std::string& text) -> std::string {
                             Pose p;
                             return parsePose(text, p) ? std::string()
                                                       : "must be yaw,pitch,roll,x,y,z (degrees, "
                                                         "then metres), got '" +
                                                             text + "'";
                         },
                         "YAW,PITCH,ROLL,X,Y,Z", "POSE"));
    cmd->add_option("--spawn", opts->spawn, "Stand at this spawn point (default: the first)")
        ->check(CLI::Range(0, 100000))
        ->excludes(pose);
    addGazePointOption(cmd, opts->gaze);
    cmd->add_option("--e1", opts->e1_deg, "Fovea radius e1 in degrees of eccentricity")
        ->check(finiteRange(0.0, 180.0))
        ->capture_default_str();
    addProfileOption(cmd, opts->profile);
    cmd->add_option("--ipd-mm", opts->ipd_mm, "Interpupillary distance in millimetres")
        ->check(finiteRange(0.0, 100.0))
        ->capture_default_str();
    cmd->add_option("--lightmap-gain", opts->lightmap_gain,
                    "Extra lightmap brightening on top of the loader's overbright shift")
        ->check(finiteRange(0.0, 16.0))
        ->capture_default_str();
    addLodOption(cmd, opts->lod_px);
    cmd->add_option("--msaa", opts->msaa, "Samples per pixel (1: no multisampling)")
        ->check(CLI::Range(1, 32))
        ->capture_default_str();
    cmd->add_option("--out", opts->out_dir, "Directory for the PNGs ({eye}_{layer}.png)")
        ->required()
        ->check(outputFolder());
    cmd->add_flag("--json", opts->json, "Print machine-readable JSON");
    Action action = [opts]() -> int { return run(*opts); };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(70, registerRender);

}  // namespace qvr::cli
