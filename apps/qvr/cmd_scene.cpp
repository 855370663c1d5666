// `qvr scene info SCENE` and `qvr scene count SCENE`: load a scene (Quake III level, glTF/OBJ
// file or built-in), report what the renderer will draw, and count the triangles a view
// processes per eccentricity ring — LIWC's "hardware intermediate data" (paper §4.1).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr::cli {

namespace {

struct SceneOptions {
    std::string scene;
    int patch_level = SceneLoadOptions{}.patch_level;
    bool no_textures = false;
    bool json = false;
    // count
    int spawn = 0;
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    std::string gaze = "0,0";
    std::string profile = "default";
    double ring_deg = 5.0;
    int rings = 0;
    double e1_deg = 15.0;
    double near_m = 0.05;
    double far_m = 1000.0;
    bool brute_force = false;
};

nlohmann::json vecJson(const glm::vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int loadFor(const char* cmd, const SceneOptions& o, Scene& scene, SceneLoadReport& report,
            double& load_ms) {
    SceneLoadOptions lo;
    lo.patch_level = o.patch_level;
    lo.load_textures = !o.no_textures;
    const auto t0 = std::chrono::steady_clock::now();
    auto loaded = loadScene(o.scene, lo, &report);
    load_ms = msSince(t0);
    if (!loaded) {
        std::fprintf(stderr, "qvr scene %s: %s\n", cmd, loaded.error().c_str());
        return 2;
    }
    scene = std::move(*loaded);
    return 0;
}

int runInfo(const SceneOptions& o) {
    Scene scene;
    SceneLoadReport report;
    double load_ms = 0;
    if (int rc = loadFor("info", o, scene, report, load_ms); rc != 0)
        return rc;
    const auto t1 = std::chrono::steady_clock::now();
    const TriangleBvh bvh(scene);
    const double bvh_ms = msSince(t1);
    const SceneTriangleCounts counts = countSceneTriangles(scene);
    uint64_t texture_bytes = 0;
    for (const auto& t : scene.textures)
        texture_bytes += t.rgba.size();
    const BspStats& b = report.bsp;
    if (o.json) {
        nlohmann::json j;
        j["scene"] = scene.name;
        j["format"] = report.format;
        j["triangles"] = counts.triangles;
        j["patch_triangles"] = counts.patch_triangles;
        j["total_triangles"] = counts.total();
        j["patch_level"] = o.patch_level;
        j["vertices"] = scene.vertices.size();
        j["batches"] = scene.batches.size();
        j["textures"] = scene.textures.size();
        j["texture_bytes"] = texture_bytes;
        j["lightmaps"] = scene.lightmaps.size();
        j["bounds"] = {{"min", vecJson(scene.bounds.min)},
                       {"max", vecJson(scene.bounds.max)},
                       {"size", vecJson(scene.bounds.max - scene.bounds.min)}};
        nlohmann::json spawns = nlohmann::json::array();
        for (const auto& s : scene.spawns)
            spawns.push_back({{"position_m", vecJson(s.position_m)}, {"yaw_deg", s.yaw_deg}});
        j["spawns"] = spawns;
        if (report.format == "ibsp46") {
            j["faces"] = {{"total", b.faces},
                          {"drawn", b.faces_drawn},
                          {"sky_nodraw_fog", b.faces_sky_or_nodraw},
                          {"bad_shader", b.faces_bad_shader},
                          {"flare_or_unknown", b.faces_flare_or_unknown},
                          {"empty", b.faces_empty}};
            j["shaders_without_image"] = b.missing_images;
        }
        j["bvh_nodes"] = bvh.nodeCount();
        j["load_ms"] = load_ms;
        j["bvh_build_ms"] = bvh_ms;
        j["units"] = "metres, y up, -z forward";
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    const glm::vec3 size = scene.bounds.max - scene.bounds.min;
    fmt::print("{} ({})\n", scene.name, report.format);
    fmt::print("  triangles        {} (+ {} in Bezier patches at level {}) = {}\n",
               counts.triangles, counts.patch_triangles, o.patch_level, counts.total());
    fmt::print("  vertices         {}\n", scene.vertices.size());
    fmt::print("  batches          {}\n", scene.batches.size());
    fmt::print("  textures         {} ({:.1f} MB RGBA)\n", scene.textures.size(),
               static_cast<double>(texture_bytes) / 1e6);
    fmt::print("  lightmaps        {}\n", scene.lightmaps.size());
    fmt::print(
        "  bounds           ({:.2f}, {:.2f}, {:.2f}) .. ({:.2f}, {:.2f}, {:.2f}) m, "
        "{:.1f} x {:.1f} x {:.1f} m\n",
        scene.bounds.min.x, scene.bounds.min.y, scene.bounds.min.z, scene.bounds.max.x,
        scene.bounds.max.y, scene.bounds.max.z, size.x, size.y, size.z);
    if (report.format == "ibsp46")
        fmt::print(
            "  faces            {} drawn of {} ({} sky/nodraw/fog, {} bad shader, {} "
            "flare/other); {} shaders without an image\n",
            b.faces_drawn, b.faces, b.faces_sky_or_nodraw, b.faces_bad_shader,
            b.faces_flare_or_unknown, b.shaders_without_image);
    fmt::print("  spawn points     {}\n", scene.spawns.size());
    for (const auto& s : scene.spawns)
        fmt::print("    ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.0f} deg\n", s.position_m.x,
                   s.position_m.y, s.position_m.z, s.yaw_deg);
    fmt::print("  loaded in {:.0f} ms, BVH ({} nodes) built in {:.0f} ms\n", load_ms,
               bvh.nodeCount(), bvh_ms);
    return 0;
}

int runCount(const SceneOptions& o) {
    Gaze gaze;
    parseGazeDeg(o.gaze, gaze);  // checked when parsed
    if (!(o.near_m > 0.0 && o.far_m > o.near_m)) {
        std::fprintf(stderr, "qvr scene count: need 0 < --near-m < --far-m\n");
        return 2;
    }
    auto profile = hmdProfileByName(o.profile);
    if (!profile) {
        std::fprintf(stderr, "qvr scene count: %s\n", profile.error().c_str());
        return 2;
    }
    Scene scene;
    SceneLoadReport report;
    double load_ms = 0;
    SceneOptions lo = o;
    lo.no_textures = true;  // counting needs geometry only
    if (int rc = loadFor("count", lo, scene, report, load_ms); rc != 0)
        return rc;
    if (scene.spawns.empty() || o.spawn < 0 || o.spawn >= static_cast<int>(scene.spawns.size())) {
        std::fprintf(stderr, "qvr scene count: %s has %zu spawn points, --spawn %d is not one\n",
                     scene.name.c_str(), scene.spawns.size(), o.spawn);
        return 2;
    }
    const SpawnPoint& sp = scene.spawns[static_cast<size_t>(o.spawn)];
    const glm::dquat orientation(quatFromEulerDeg({sp.yaw_deg + o.yaw_deg, o.pitch_deg, 0.0}));
    const EyeView view =
        EyeView::symmetric(glm::dvec3(sp.position_m), orientation, profile->fov_h_deg,
                           profile->fov_v_deg, o.near_m, o.far_m);
    const EyeGeometry geometry(*profile);
    const glm::dvec3 gaze_eye = geometry.gazeDirection(gaze);
    const int rings =
        o.rings > 0
            ? o.rings
            : static_cast<int>(std::ceil(geometry.coverEccentricityDeg(gaze) / o.ring_deg)) + 1;
    const auto t0 = std::chrono::steady_clock::now();
    const TriangleBvh bvh(scene);
    const double build_ms = msSince(t0);
    BvhQueryStats ring_stats, cone_stats;
    auto t1 = std::chrono::steady_clock::now();
    const std::vector<uint64_t> hist =
        bvh.trianglesPerRing(view, gaze_eye, o.ring_deg, rings, &ring_stats);
    const double rings_ms = msSince(t1);
    const ViewCone cone{view.position_m, orientation * gaze_eye, o.e1_deg, o.near_m, o.far_m};
    t1 = std::chrono::steady_clock::now();
    const uint64_t in_cone = bvh.countTrianglesInCone(cone, &cone_stats);
    const double cone_ms = msSince(t1);
    uint64_t in_view = 0;
    for (uint64_t n : hist)
        in_view += n;
    double brute_ms = -1.0;
    uint64_t outcode_count = 0;
    bool brute_agrees = true;
    if (o.brute_force) {
        t1 = std::chrono::steady_clock::now();
        brute_agrees = bvh.trianglesPerRingBruteForce(view, gaze_eye, o.ring_deg, rings) == hist &&
                       bvh.countTrianglesInConeBruteForce(cone) == in_cone;
        brute_ms = msSince(t1);
        outcode_count = bvh.countTrianglesByOutcodes(view);
    }
    if (o.json) {
        nlohmann::json j;
        j["scene"] = scene.name;
        j["triangles"] = bvh.triangleCount();
        j["spawn"] = o.spawn;
        j["eye_position_m"] = vecJson(sp.position_m);
        j["yaw_deg"] = sp.yaw_deg + o.yaw_deg;
        j["pitch_deg"] = o.pitch_deg;
        j["profile"] = profile->name;
        j["fov_deg"] = {profile->fov_h_deg, profile->fov_v_deg};
        j["near_m"] = o.near_m;
        j["far_m"] = o.far_m;
        j["gaze_deg"] = {gaze.x_deg, gaze.y_deg};
        j["ring_deg"] = o.ring_deg;
        j["triangles_in_view"] = in_view;
        j["triangles_per_ring"] = hist;
        j["e1_deg"] = o.e1_deg;
        j["triangles_in_fovea_cone"] = in_cone;
        j["bvh_build_ms"] = build_ms;
        j["rings_ms"] = rings_ms;
        j["cone_ms"] = cone_ms;
        j["rings_nodes_visited"] = ring_stats.nodes_visited;
        j["rings_triangles_tested"] = ring_stats.triangles_tested;
        if (o.brute_force) {
            j["brute_force_ms"] = brute_ms;
            j["brute_force_agrees"] = brute_agrees;
            j["triangles_not_trivially_rejected"] = outcode_count;
        }
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        fmt::print(
            "{}: spawn {} at ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.0f}, pitch {:.0f}; {} "
            "{:.0f}x{:.0f} deg, near {} m, far {} m, gaze ({}, {}) deg\n",
            scene.name, o.spawn, sp.position_m.x, sp.position_m.y, sp.position_m.z,
            sp.yaw_deg + o.yaw_deg, o.pitch_deg, profile->name, profile->fov_h_deg,
            profile->fov_v_deg, o.near_m, o.far_m, gaze.x_deg, gaze.y_deg);
        fmt::print("  {} of {} triangles in the view frustum\n", in_view, bvh.triangleCount());
        fmt::print("  {} in the {:.1f} deg fovea cone\n", in_cone, o.e1_deg);
        uint64_t prefix = 0;
        for (size_t k = 0; k < hist.size(); ++k) {
            prefix += hist[k];
            const bool last = k + 1 == hist.size();
            fmt::print("  ring {:5.1f}-{:<5} deg {:9} (within: {})\n", k * o.ring_deg,
                       last ? std::string("...") : fmt::format("{:.1f}", (k + 1) * o.ring_deg),
                       hist[k], prefix);
        }
        fmt::print(
            "  BVH built in {:.0f} ms; rings {:.2f} ms ({} nodes, {} triangle tests), "
            "cone {:.2f} ms\n",
            build_ms, rings_ms, ring_stats.nodes_visited, ring_stats.triangles_tested, cone_ms);
        if (o.brute_force) {
            fmt::print("  brute force {:.0f} ms, {}\n", brute_ms,
                       brute_agrees ? "same counts" : "DIFFERENT COUNTS");
            fmt::print("  {} triangles pass a GPU's outcode trivial-reject test\n", outcode_count);
        }
    }
    return brute_agrees ? 0 : 1;
}

}  // namespace

static Registered registerScene(CLI::App& app) {
    auto opts = std::make_shared<SceneOptions>();
    CLI::App* cmd = app.add_subcommand("scene", "Inspect scenes and count their triangles");
    cmd->require_subcommand(1);
    const char* scene_help =
        "openarena:MAP, nexuiz:MAP, builtin:room[?objects=N], or a .bsp/.pk3/.gltf/.glb/.obj file";
    auto common = [&](CLI::App* sub) {
        sub->add_option("SCENE", opts->scene, scene_help)->required();
        sub->add_option("--patch-level", opts->patch_level,
                        "Quads per side of each Bezier sub-patch (Quake III patches)")
            ->check(CLI::Range(1, 64))
            ->capture_default_str();
        sub->add_flag("--json", opts->json, "Print machine-readable JSON");
    };
    CLI::App* info = cmd->add_subcommand("info", "Load a scene and print its size and contents");
    common(info);
    info->add_flag("--no-textures", opts->no_textures, "Skip decoding textures (faster)");
    CLI::App* count = cmd->add_subcommand(
        "count", "Triangles a view from a spawn point processes, per eccentricity ring");
    common(count);
    count->add_option("--spawn", opts->spawn, "Spawn point index")->capture_default_str();
    count->add_option("--yaw", opts->yaw_deg, "Degrees added to the spawn's yaw")
        ->check(finiteRange(-360.0, 360.0));
    count->add_option("--pitch", opts->pitch_deg, "Head pitch in degrees (up positive)")
        ->check(finiteRange(-89.0, 89.0));
    addGazePointOption(count, opts->gaze);
    addProfileOption(count, opts->profile);
    count->add_option("--ring-deg", opts->ring_deg, "Ring width in degrees")
        ->check(finiteRange(0.1, 90.0))
        ->capture_default_str();
    count->add_option("--rings", opts->rings, "Rings (0: enough to cover the image)")
        ->check(CLI::Range(0, 1800));
    count->add_option("--e1", opts->e1_deg, "Fovea cone radius in degrees")
        ->check(finiteRange(0.01, 89.9))
        ->capture_default_str();
    count->add_option("--near-m", opts->near_m, "Near plane (metres)")
        ->check(finiteNumber())
        ->capture_default_str();
    count->add_option("--far-m", opts->far_m, "Far plane (metres)")
        ->check(finiteNumber())
        ->capture_default_str();
    count->add_flag("--brute-force", opts->brute_force,
                    "Also count by testing every triangle, and compare");
    Action action = [opts, info, count]() -> int {
        if (info->parsed())
            return runInfo(*opts);
        if (count->parsed())
            return runCount(*opts);
        return 2;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(60, registerScene);

}  // namespace qvr::cli
