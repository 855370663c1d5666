// `qvr scene info SCENE` and `qvr scene count SCENE`: load a scene (Quake III level, glTF/OBJ
// file or built-in), report what the renderer will draw, and count the triangles a view
// processes per eccentricity ring (scene/scene_survey.h).
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/scene/scene_survey.h"

namespace qvr::cli {

namespace {

struct SceneOptions {
    std::string scene;
    SceneLoadOptions load;
    bool json = false;
    bool no_textures = false;
    // count
    int rings = 0;  // 0: enough to cover the image
    int spawn = 0;
    std::string gaze = "0,0";
    std::string profile = "default";
    SceneCountPlan plan;
};

int runInfo(const SceneOptions& o) {
    SceneLoadOptions load = o.load;
    load.load_textures = !o.no_textures;
    auto info = surveyScene(o.scene, load);
    if (!info) {
        std::fprintf(stderr, "qvr scene info: %s\n", info.error().c_str());
        return 2;
    }
    printReport(o.json, sceneInfoJson(*info), sceneInfoText(*info));
    return 0;
}

int runCount(const SceneOptions& o) {
    constexpr const char* kCmd = "qvr scene count";
    if (!(o.plan.near_m > 0.0 && o.plan.far_m > o.plan.near_m)) {
        std::fprintf(stderr, "%s: need 0 < --near-m < --far-m\n", kCmd);
        return 2;
    }
    SceneLoadOptions load = o.load;
    load.load_textures = false;  // counting needs geometry only
    auto scene = loadScene(o.scene, load);
    if (!scene) {
        std::fprintf(stderr, "%s: %s\n", kCmd, scene.error().c_str());
        return 2;
    }
    if (o.spawn < 0 || o.spawn >= static_cast<int>(scene->spawns.size())) {
        std::fprintf(stderr, "%s: %s has %zu spawn points, --spawn %d is not one\n", kCmd,
                     scene->name.c_str(), scene->spawns.size(), o.spawn);
        return 2;
    }
    const HmdProfile profile = checkedHmdProfile(o.profile);
    const Gaze gaze = checkedGaze(o.gaze);
    const EyeGeometry geometry(profile);
    SceneCountPlan plan = o.plan;
    plan.spawn = static_cast<size_t>(o.spawn);
    plan.profile = profile.name;
    plan.fov_h_deg = profile.fov_h_deg;
    plan.fov_v_deg = profile.fov_v_deg;
    plan.gaze_x_deg = gaze.x_deg;
    plan.gaze_y_deg = gaze.y_deg;
    plan.gaze_dir_eye = geometry.gazeDirection(gaze);
    plan.rings =
        o.rings > 0
            ? o.rings
            : static_cast<int>(std::ceil(geometry.coverEccentricityDeg(gaze) / plan.ring_deg)) + 1;
    const SceneCount count = countSceneView(*scene, plan);
    printReport(o.json, sceneCountJson(count), sceneCountText(count));
    return count.brute_force_agrees ? 0 : 1;
}

}  // namespace

static Registered registerScene(CLI::App& app) {
    auto o = std::make_shared<SceneOptions>();
    CLI::App* cmd = app.add_subcommand("scene", "Inspect scenes and count their triangles")
                        ->require_subcommand(1);
    auto common = [&](CLI::App* sub) {
        sub->add_option("SCENE", o->scene, kSceneHelp)->required();
        addInt(sub, "--patch-level", o->load.patch_level,
               "Quads per side of each Bezier sub-patch (Quake III patches)", 1, 64);
        addJsonFlag(sub, o->json);
    };
    CLI::App* info = cmd->add_subcommand("info", "Load a scene and print its size and contents");
    common(info);
    info->add_flag("--no-textures", o->no_textures, "Skip decoding textures (faster)");
    CLI::App* count = cmd->add_subcommand(
        "count", "Triangles a view from a spawn point processes, per eccentricity ring");
    common(count);
    SceneCountPlan& p = o->plan;
    count->add_option("--spawn", o->spawn, "Spawn point index")->capture_default_str();
    count->add_option("--yaw", p.yaw_deg, "Degrees added to the spawn's yaw")
        ->check(finiteRange(-360.0, 360.0));
    count->add_option("--pitch", p.pitch_deg, "Head pitch in degrees (up positive)")
        ->check(finiteRange(-89.0, 89.0));
    addGazePointOption(count, o->gaze);
    addProfileOption(count, o->profile);
    addFinite(count, "--ring-deg", p.ring_deg, "Ring width in degrees", 0.1, 90.0);
    count->add_option("--rings", o->rings, "Rings (0: enough to cover the image)")
        ->check(CLI::Range(0, 1800));
    addFinite(count, "--e1", p.e1_deg, "Fovea cone radius in degrees", 0.01, 89.9);
    count->add_option("--near-m", p.near_m, "Near plane (metres)")
        ->check(finiteNumber())
        ->capture_default_str();
    count->add_option("--far-m", p.far_m, "Far plane (metres)")
        ->check(finiteNumber())
        ->capture_default_str();
    count->add_flag("--brute-force", p.brute_force,
                    "Also count by testing every triangle, and compare");
    Action action = [o, info]() -> int { return info->parsed() ? runInfo(*o) : runCount(*o); };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(60, registerScene);

}  // namespace qvr::cli
