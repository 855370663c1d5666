// What `qvr scene info` and `qvr scene count` report: a scene's size and contents, and the
// triangles one view of it processes per eccentricity ring — LIWC's "hardware intermediate data"
// (paper §4.1). Each is a plan in, a result out, and a JSON object or text read from the result.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr {

struct SceneInfo {
    std::string name;
    std::string format;  // SceneLoadReport::format
    int patch_level = 0;
    SceneTriangleCounts counts;
    size_t vertices = 0;
    size_t batches = 0;
    size_t textures = 0;
    uint64_t texture_bytes = 0;  // RGBA
    size_t lightmaps = 0;
    Aabb bounds;
    std::vector<SpawnPoint> spawns;
    BspStats bsp;  // Quake III levels only
    size_t bvh_nodes = 0;
    double load_ms = 0.0;
    double bvh_build_ms = 0.0;
};

// Loads the scene, builds its BVH, and times both.
Expected<SceneInfo> surveyScene(const std::string& name, const SceneLoadOptions& options);
nlohmann::json sceneInfoJson(const SceneInfo& info);
std::string sceneInfoText(const SceneInfo& info);

// One view from a spawn point; the caller states the frustum and the gaze direction (the
// foveation part's EyeGeometry knows them), the rest is counted here.
struct SceneCountPlan {
    size_t spawn = 0;        // index into Scene::spawns
    double yaw_deg = 0.0;    // added to the spawn's yaw
    double pitch_deg = 0.0;  // up positive
    std::string profile;     // the display profile's name, for the report
    double fov_h_deg = 90.0;
    double fov_v_deg = 90.0;
    double near_m = 0.05;
    double far_m = 1000.0;
    double gaze_x_deg = 0.0;  // the gaze, for the report
    double gaze_y_deg = 0.0;
    glm::dvec3 gaze_dir_eye{0.0, 0.0, -1.0};  // the gaze as a direction in eye space
    double ring_deg = 5.0;
    int rings = 1;
    double e1_deg = 15.0;      // fovea cone radius
    bool brute_force = false;  // also count by testing every triangle
};

struct SceneCount {
    SceneCountPlan plan;
    std::string scene;
    size_t triangles = 0;
    glm::vec3 eye_position_m{0.0f};
    double yaw_deg = 0.0;  // the spawn's yaw plus the plan's
    uint64_t in_view = 0;
    std::vector<uint64_t> per_ring;
    uint64_t in_cone = 0;
    BvhQueryStats ring_stats;
    double bvh_build_ms = 0.0;
    double rings_ms = 0.0;
    double cone_ms = 0.0;
    // With brute_force only:
    double brute_force_ms = -1.0;
    bool brute_force_agrees = true;
    uint64_t not_trivially_rejected = 0;  // triangles passing the outcode trivial-reject test
};

// Counts the plan's view of `scene`; plan.spawn must be one of its spawn points.
SceneCount countSceneView(const Scene& scene, const SceneCountPlan& plan);
nlohmann::json sceneCountJson(const SceneCount& count);
std::string sceneCountText(const SceneCount& count);

}  // namespace qvr
