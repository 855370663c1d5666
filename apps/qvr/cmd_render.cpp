// `qvr render SCENE`: render one frame's layers (paper §3.2) and a full-frame reference per eye
// as PNGs a person can look at (render/frame_layers.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/compose/png_io.h"
#include "qvr/render/frame_layers.h"
#include "qvr/scene/scene_loader.h"

namespace qvr::cli {

namespace {

struct RenderOptions {
    std::string scene;
    std::string pose;
    int spawn = -1;
    std::string gaze = "0,0";
    std::string profile = "default";
    double ipd_mm = 64.0;
    std::string out_dir;
    bool json = false;
    FrameLayersPlan plan;
};

// "yaw,pitch,roll,x,y,z": degrees, then metres.
bool parsePose(const std::string& text, Pose& pose) {
    double v[6];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &v[3], &v[4],
                    &v[5], &tail) != 6)
        return false;
    for (double x : v)
        if (!std::isfinite(x) || std::fabs(x) > 1e5)
            return false;
    pose.orientation = quatFromEulerDeg({v[0], v[1], v[2]});
    pose.position_m = {static_cast<float>(v[3]), static_cast<float>(v[4]),
                       static_cast<float>(v[5])};
    return true;
}

int run(const RenderOptions& o) {
    constexpr const char* kCmd = "qvr render";
    auto scene = loadScene(o.scene);
    if (!scene) {
        std::fprintf(stderr, "%s: %s\n", kCmd, scene.error().c_str());
        return 2;
    }
    FrameLayersPlan plan = o.plan;
    plan.profile = checkedHmdProfile(o.profile);
    plan.gaze = checkedGaze(o.gaze);
    plan.camera.ipd_m = o.ipd_mm * 1e-3;
    if (!o.pose.empty()) {
        parsePose(o.pose, plan.head);  // checked when parsed
        plan.pose_source = "--pose";
    } else if (o.spawn >= static_cast<int>(scene->spawns.size())) {
        std::fprintf(stderr, "%s: --spawn %d, but %s has %zu spawn points\n", kCmd, o.spawn,
                     scene->name.c_str(), scene->spawns.size());
        return 2;
    } else if (!scene->spawns.empty()) {
        // Stand where a player would: the requested spawn point, else the first one.
        const int spawn = std::max(o.spawn, 0);
        plan.head = poseFromSpawn(scene->spawns[static_cast<size_t>(spawn)]);
        plan.pose_source = fmt::format("spawn {}", spawn);
    }
    auto sink = [&o](Eye eye, const std::string& layer,
                     const ImageRgba8& image) -> Expected<std::string> {
        const std::filesystem::path path =
            std::filesystem::path(o.out_dir) / fmt::format("{}_{}.png", eyeName(eye), layer);
        if (Status s = writePng(path.string(), image); !s)
            return makeError(s.error());
        return path.string();
    };
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) {
        std::fprintf(stderr, "%s: cannot create --out directory '%s': %s\n", kCmd,
                     o.out_dir.c_str(), ec.message().c_str());
        return 1;
    }
    auto frame = renderFrameLayers(*scene, plan, sink);
    if (!frame) {
        std::fprintf(stderr, "%s: %s\n", kCmd, frame.error().c_str());
        return 1;
    }
    printReport(o.json, frameLayersJson(*frame), frameLayersText(*frame));
    return 0;
}

}  // namespace

static Registered registerRender(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render", "Render a frame's fovea/middle/outer layers and full frames per eye to PNG");
    cmd->add_option("SCENE", o->scene, kSceneHelp)->required();
    auto* pose = cmd->add_option("--pose", o->pose,
                                 "Head pose yaw,pitch,roll,x,y,z (degrees, metres; y up, -z "
                                 "forward)")
                     ->check(parsedBy(&parsePose, "yaw,pitch,roll,x,y,z (degrees, then metres)",
                                      "YAW,PITCH,ROLL,X,Y,Z", "POSE"));
    cmd->add_option("--spawn", o->spawn, "Stand at this spawn point (default: the first)")
        ->check(CLI::Range(0, 100000))
        ->excludes(pose);
    addGazePointOption(cmd, o->gaze);
    addE1Option(cmd, o->plan.e1_deg, 180.0);
    addProfileOption(cmd, o->profile);
    addFinite(cmd, "--ipd-mm", o->ipd_mm, "Interpupillary distance in millimetres", 0.0, 100.0);
    addFinite(cmd, "--lightmap-gain", o->plan.renderer.lightmap_gain,
              "Extra lightmap brightening on top of the loader's overbright shift", 0.0, 16.0);
    addLodOption(cmd, o->plan.renderer.lod_error_px);
    addMsaaOption(cmd, o->plan.renderer.msaa_samples);
    addOutputFolderOption(cmd, o->out_dir, "Directory for the PNGs ({eye}_{layer}.png)")
        ->required();
    addJsonFlag(cmd, o->json);
    return {cmd, [o]() { return run(*o); }};
}

QVR_REGISTER_COMMAND(70, registerRender);

}  // namespace qvr::cli
