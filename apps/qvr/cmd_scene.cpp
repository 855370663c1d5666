// `qvr scene info SCENE [--json]`: load a scene (Quake III level, glTF/OBJ file or built-in)
// and report what the renderer and LIWC's triangle counter will see.
#include <chrono>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr::cli {

namespace {

struct SceneInfoOptions {
    std::string scene;
    int patch_level = SceneLoadOptions{}.patch_level;
    bool no_textures = false;
    bool json = false;
};

nlohmann::json vecJson(const glm::vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

}  // namespace

static Registered registerScene(CLI::App& app) {
    auto opts = std::make_shared<SceneInfoOptions>();
    CLI::App* cmd =
        app.add_subcommand("scene", "Inspect scenes (Quake III levels, glTF/OBJ, built-in)");
    cmd->require_subcommand(1);
    CLI::App* info = cmd->add_subcommand("info", "Load a scene and print its size and contents");
    info->add_option("SCENE", opts->scene,
                     "openarena:MAP, nexuiz:MAP, builtin:room[?objects=N], or a "
                     ".bsp/.pk3/.gltf/.glb/.obj file")
        ->required();
    info->add_option("--patch-level", opts->patch_level,
                     "Quads per side of each Bezier sub-patch (Quake III patches)")
        ->check(CLI::Range(1, 64))
        ->capture_default_str();
    info->add_flag("--no-textures", opts->no_textures, "Skip decoding textures (faster)");
    info->add_flag("--json", opts->json, "Print machine-readable JSON");
    Action action = [opts]() -> int {
        SceneLoadOptions lo;
        lo.patch_level = opts->patch_level;
        lo.load_textures = !opts->no_textures;
        const auto t0 = std::chrono::steady_clock::now();
        auto scene = loadScene(opts->scene, lo);
        const auto t1 = std::chrono::steady_clock::now();
        if (!scene) {
            std::fprintf(stderr, "qvr scene info: %s\n", scene.error().c_str());
            return 2;
        }
        const TriangleBvh bvh(*scene);
        const auto t2 = std::chrono::steady_clock::now();
        const SceneTriangleCounts counts = countSceneTriangles(*scene);
        uint64_t texture_bytes = 0;
        for (const auto& t : scene->textures)
            texture_bytes += t.rgba.size();
        uint64_t lightmap_bytes = 0;
        for (const auto& t : scene->lightmaps)
            lightmap_bytes += t.rgba.size();
        const double load_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
        const double bvh_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
        if (opts->json) {
            nlohmann::json j;
            j["scene"] = scene->name;
            j["triangles"] = counts.triangles;
            j["patch_triangles"] = counts.patch_triangles;
            j["total_triangles"] = counts.total();
            j["patch_level"] = lo.patch_level;
            j["vertices"] = scene->vertices.size();
            j["batches"] = scene->batches.size();
            j["textures"] = scene->textures.size();
            j["texture_bytes"] = texture_bytes;
            j["lightmaps"] = scene->lightmaps.size();
            j["lightmap_bytes"] = lightmap_bytes;
            j["bounds"] = {{"min", vecJson(scene->bounds.min)},
                           {"max", vecJson(scene->bounds.max)},
                           {"size", vecJson(scene->bounds.max - scene->bounds.min)}};
            nlohmann::json spawns = nlohmann::json::array();
            for (const auto& s : scene->spawns)
                spawns.push_back({{"position_m", vecJson(s.position_m)}, {"yaw_deg", s.yaw_deg}});
            j["spawns"] = spawns;
            j["bvh_nodes"] = bvh.nodeCount();
            j["load_ms"] = load_ms;
            j["bvh_build_ms"] = bvh_ms;
            j["units"] = "metres, y up, -z forward";
            std::printf("%s\n", j.dump(2).c_str());
            return 0;
        }
        const glm::vec3 size = scene->bounds.max - scene->bounds.min;
        fmt::print("{}\n", scene->name);
        fmt::print("  triangles        {} (+ {} in Bezier patches at level {}) = {}\n",
                   counts.triangles, counts.patch_triangles, lo.patch_level, counts.total());
        fmt::print("  vertices         {}\n", scene->vertices.size());
        fmt::print("  batches          {}\n", scene->batches.size());
        fmt::print("  textures         {} ({:.1f} MB RGBA)\n", scene->textures.size(),
                   static_cast<double>(texture_bytes) / 1e6);
        fmt::print("  lightmaps        {}\n", scene->lightmaps.size());
        fmt::print(
            "  bounds           ({:.2f}, {:.2f}, {:.2f}) .. ({:.2f}, {:.2f}, {:.2f}) m, "
            "{:.1f} x {:.1f} x {:.1f} m\n",
            scene->bounds.min.x, scene->bounds.min.y, scene->bounds.min.z, scene->bounds.max.x,
            scene->bounds.max.y, scene->bounds.max.z, size.x, size.y, size.z);
        fmt::print("  spawn points     {}\n", scene->spawns.size());
        for (const auto& s : scene->spawns)
            fmt::print("    ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.0f} deg\n", s.position_m.x,
                       s.position_m.y, s.position_m.z, s.yaw_deg);
        fmt::print("  loaded in {:.0f} ms, BVH ({} nodes) built in {:.0f} ms\n", load_ms,
                   bvh.nodeCount(), bvh_ms);
        return 0;
    };
    // The action runs when `info` was the chosen subcommand; CLI11 requires one.
    return {info, action};
}

QVR_REGISTER_COMMAND(60, registerScene);

}  // namespace qvr::cli
