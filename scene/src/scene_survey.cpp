#include "qvr/scene/scene_survey.h"

#include <chrono>

#include <fmt/format.h>

#include "qvr/core/check.h"
#include "qvr/core/pose.h"

namespace qvr {

namespace {

using SteadyClock = std::chrono::steady_clock;

double msSince(SteadyClock::time_point t0) {
    return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

nlohmann::json vecJson(const glm::vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

}  // namespace

Expected<SceneInfo> surveyScene(const std::string& name, const SceneLoadOptions& options) {
    SceneLoadReport report;
    const auto t0 = SteadyClock::now();
    auto scene = loadScene(name, options, &report);
    const double load_ms = msSince(t0);
    if (!scene)
        return makeError(scene.error());
    SceneInfo info;
    info.name = scene->name;
    info.format = report.format;
    info.patch_level = options.patch_level;
    info.counts = countSceneTriangles(*scene);
    info.vertices = scene->vertices.size();
    info.batches = scene->batches.size();
    info.textures = scene->textures.size();
    for (const auto& t : scene->textures)
        info.texture_bytes += t.rgba.size();
    info.lightmaps = scene->lightmaps.size();
    info.bounds = scene->bounds;
    info.spawns = scene->spawns;
    info.bsp = report.bsp;
    info.load_ms = load_ms;
    const auto t1 = SteadyClock::now();
    info.bvh_nodes = TriangleBvh(*scene).nodeCount();
    info.bvh_build_ms = msSince(t1);
    return info;
}

nlohmann::json sceneInfoJson(const SceneInfo& s) {
    nlohmann::json j;
    j["scene"] = s.name;
    j["format"] = s.format;
    j["triangles"] = s.counts.triangles;
    j["patch_triangles"] = s.counts.patch_triangles;
    j["total_triangles"] = s.counts.total();
    j["patch_level"] = s.patch_level;
    j["vertices"] = s.vertices;
    j["batches"] = s.batches;
    j["textures"] = s.textures;
    j["texture_bytes"] = s.texture_bytes;
    j["lightmaps"] = s.lightmaps;
    j["bounds"] = {{"min", vecJson(s.bounds.min)},
                   {"max", vecJson(s.bounds.max)},
                   {"size", vecJson(s.bounds.max - s.bounds.min)}};
    nlohmann::json spawns = nlohmann::json::array();
    for (const auto& p : s.spawns)
        spawns.push_back({{"position_m", vecJson(p.position_m)}, {"yaw_deg", p.yaw_deg}});
    j["spawns"] = spawns;
    if (s.format == "ibsp46") {
        const BspStats& b = s.bsp;
        j["faces"] = {{"total", b.faces},
                      {"drawn", b.faces_drawn},
                      {"sky_nodraw_fog", b.faces_sky_or_nodraw},
                      {"bad_shader", b.faces_bad_shader},
                      {"flare_or_unknown", b.faces_flare_or_unknown},
                      {"empty", b.faces_empty}};
        j["shaders_without_image"] = b.missing_images;
    }
    j["bvh_nodes"] = s.bvh_nodes;
    j["load_ms"] = s.load_ms;
    j["bvh_build_ms"] = s.bvh_build_ms;
    j["units"] = "metres, y up, -z forward";
    return j;
}

std::string sceneInfoText(const SceneInfo& s) {
    const glm::vec3 size = s.bounds.max - s.bounds.min;
    const Aabb& b = s.bounds;
    std::string out = fmt::format("{} ({})\n", s.name, s.format);
    out +=
        fmt::format("  triangles        {} (+ {} in Bezier patches at level {}) = {}\n",
                    s.counts.triangles, s.counts.patch_triangles, s.patch_level, s.counts.total());
    out += fmt::format("  vertices         {}\n", s.vertices);
    out += fmt::format("  batches          {}\n", s.batches);
    out += fmt::format("  textures         {} ({:.1f} MB RGBA)\n", s.textures,
                       static_cast<double>(s.texture_bytes) / 1e6);
    out += fmt::format("  lightmaps        {}\n", s.lightmaps);
    out += fmt::format(
        "  bounds           ({:.2f}, {:.2f}, {:.2f}) .. ({:.2f}, {:.2f}, {:.2f}) m, "
        "{:.1f} x {:.1f} x {:.1f} m\n",
        b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z, size.x, size.y, size.z);
    if (s.format == "ibsp46")
        out += fmt::format(
            "  faces            {} drawn of {} ({} sky/nodraw/fog, {} bad shader, {} "
            "flare/other); {} shaders without an image\n",
            s.bsp.faces_drawn, s.bsp.faces, s.bsp.faces_sky_or_nodraw, s.bsp.faces_bad_shader,
            s.bsp.faces_flare_or_unknown, s.bsp.shaders_without_image);
    out += fmt::format("  spawn points     {}\n", s.spawns.size());
    for (const auto& p : s.spawns)
        out += fmt::format("    ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.0f} deg\n", p.position_m.x,
                           p.position_m.y, p.position_m.z, p.yaw_deg);
    out += fmt::format("  loaded in {:.0f} ms, BVH ({} nodes) built in {:.0f} ms\n", s.load_ms,
                       s.bvh_nodes, s.bvh_build_ms);
    return out;
}

SceneCount countSceneView(const Scene& scene, const SceneCountPlan& plan) {
    QVR_CHECK_MSG(plan.spawn < scene.spawns.size(), "countSceneView: no such spawn point");
    const SpawnPoint& sp = scene.spawns[plan.spawn];
    SceneCount c;
    c.plan = plan;
    c.scene = scene.name;
    c.eye_position_m = sp.position_m;
    c.yaw_deg = sp.yaw_deg + plan.yaw_deg;
    const glm::dquat orientation(quatFromEulerDeg({c.yaw_deg, plan.pitch_deg, 0.0}));
    const EyeView view = EyeView::symmetric(glm::dvec3(sp.position_m), orientation, plan.fov_h_deg,
                                            plan.fov_v_deg, plan.near_m, plan.far_m);
    auto t0 = SteadyClock::now();
    const TriangleBvh bvh(scene);
    c.bvh_build_ms = msSince(t0);
    c.triangles = bvh.triangleCount();
    t0 = SteadyClock::now();
    c.per_ring =
        bvh.trianglesPerRing(view, plan.gaze_dir_eye, plan.ring_deg, plan.rings, &c.ring_stats);
    c.rings_ms = msSince(t0);
    const ViewCone cone{view.position_m, orientation * plan.gaze_dir_eye, plan.e1_deg, plan.near_m,
                        plan.far_m};
    t0 = SteadyClock::now();
    c.in_cone = bvh.countTrianglesInCone(cone);
    c.cone_ms = msSince(t0);
    for (uint64_t n : c.per_ring)
        c.in_view += n;
    if (plan.brute_force) {
        t0 = SteadyClock::now();
        c.brute_force_agrees =
            bvh.trianglesPerRingBruteForce(view, plan.gaze_dir_eye, plan.ring_deg, plan.rings) ==
                c.per_ring &&
            bvh.countTrianglesInConeBruteForce(cone) == c.in_cone;
        c.brute_force_ms = msSince(t0);
        c.not_trivially_rejected = bvh.countTrianglesByOutcodes(view);
    }
    return c;
}

nlohmann::json sceneCountJson(const SceneCount& c) {
    const SceneCountPlan& p = c.plan;
    nlohmann::json j;
    j["scene"] = c.scene;
    j["triangles"] = c.triangles;
    j["spawn"] = p.spawn;
    j["eye_position_m"] = vecJson(c.eye_position_m);
    j["yaw_deg"] = c.yaw_deg;
    j["pitch_deg"] = p.pitch_deg;
    j["profile"] = p.profile;
    j["fov_deg"] = {p.fov_h_deg, p.fov_v_deg};
    j["near_m"] = p.near_m;
    j["far_m"] = p.far_m;
    j["gaze_deg"] = {p.gaze_x_deg, p.gaze_y_deg};
    j["ring_deg"] = p.ring_deg;
    j["triangles_in_view"] = c.in_view;
    j["triangles_per_ring"] = c.per_ring;
    j["e1_deg"] = p.e1_deg;
    j["triangles_in_fovea_cone"] = c.in_cone;
    j["bvh_build_ms"] = c.bvh_build_ms;
    j["rings_ms"] = c.rings_ms;
    j["cone_ms"] = c.cone_ms;
    j["rings_nodes_visited"] = c.ring_stats.nodes_visited;
    j["rings_triangles_tested"] = c.ring_stats.triangles_tested;
    if (p.brute_force) {
        j["brute_force_ms"] = c.brute_force_ms;
        j["brute_force_agrees"] = c.brute_force_agrees;
        j["triangles_not_trivially_rejected"] = c.not_trivially_rejected;
    }
    return j;
}

std::string sceneCountText(const SceneCount& c) {
    const SceneCountPlan& p = c.plan;
    std::string out = fmt::format(
        "{}: spawn {} at ({:.2f}, {:.2f}, {:.2f}) m, yaw {:.0f}, pitch {:.0f}; {} "
        "{:.0f}x{:.0f} deg, near {} m, far {} m, gaze ({}, {}) deg\n",
        c.scene, p.spawn, c.eye_position_m.x, c.eye_position_m.y, c.eye_position_m.z, c.yaw_deg,
        p.pitch_deg, p.profile, p.fov_h_deg, p.fov_v_deg, p.near_m, p.far_m, p.gaze_x_deg,
        p.gaze_y_deg);
    out += fmt::format("  {} of {} triangles in the view frustum\n", c.in_view, c.triangles);
    out += fmt::format("  {} in the {:.1f} deg fovea cone\n", c.in_cone, p.e1_deg);
    uint64_t prefix = 0;
    for (size_t k = 0; k < c.per_ring.size(); ++k) {
        prefix += c.per_ring[k];
        const bool last = k + 1 == c.per_ring.size();
        out += fmt::format("  ring {:5.1f}-{:<5} deg {:9} (within: {})\n", k * p.ring_deg,
                           last ? std::string("...") : fmt::format("{:.1f}", (k + 1) * p.ring_deg),
                           c.per_ring[k], prefix);
    }
    out += fmt::format(
        "  BVH built in {:.0f} ms; rings {:.2f} ms ({} nodes, {} triangle tests), "
        "cone {:.2f} ms\n",
        c.bvh_build_ms, c.rings_ms, c.ring_stats.nodes_visited, c.ring_stats.triangles_tested,
        c.cone_ms);
    if (p.brute_force) {
        out += fmt::format("  brute force {:.0f} ms, {}\n", c.brute_force_ms,
                           c.brute_force_agrees ? "same counts" : "DIFFERENT COUNTS");
        out += fmt::format("  {} triangles pass a GPU's outcode trivial-reject test\n",
                           c.not_trivially_rejected);
    }
    return out;
}

}  // namespace qvr
