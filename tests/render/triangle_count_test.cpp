// The GL side of LIWC's "hardware intermediate data" (paper §4.1): the triangles a view
// processes, counted by a geometry-shader clip test, agree with the driver's own clipper
// triangle by triangle, and (once the scene part is built) with the CPU BVH count.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <vector>

#include "hand_made_scene.h"
#include "render_test_util.h"
#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)
#include "qvr/scene/scene_loader.h"
#include "qvr/scene/triangle_bvh.h"
#endif

namespace qvr {
namespace {

Scene oneTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    Scene s;
    for (const glm::vec3& p : {a, b, c}) {
        SceneVertex v;
        v.position = p;
        s.vertices.push_back(v);
    }
    s.indices = {0, 1, 2};
    SceneBatch batch;
    batch.index_count = 3;
    s.batches.push_back(batch);
    return s;
}

TEST(TriangleCount, GeometryShaderCountAgreesWithTheDriversClipperPerTriangle) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    if (!gl->info().pipeline_statistics)
        GTEST_SKIP() << "the driver has no ARB_pipeline_statistics_query to compare with";
    const HmdProfile profile = test::smallProfile();
    Pose head;
    head.orientation = quatFromEulerDeg({30.0, 10.0, 0.0});
    const RenderView view = fullFrameView(profile, head, Eye::kLeft);
    // Small triangles scattered over a region that straddles every side plane and the near
    // plane, so that inside, outside and crossing cases (and triangles outside only near a
    // frustum corner) all occur.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> centre(-3.0f, 3.0f);
    std::uniform_real_distribution<float> depth(-3.0f, 0.5f);
    std::uniform_real_distribution<float> spread(-0.6f, 0.6f);
    int inside = 0, outside = 0, clipped_away = 0;
    ImageRgba8 img;
    for (int i = 0; i < 150; ++i) {
        const glm::vec3 c = head.orientation * glm::vec3(centre(rng), centre(rng), depth(rng));
        const glm::vec3 a = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        const glm::vec3 b = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        const glm::vec3 d = c + glm::vec3(spread(rng), spread(rng), spread(rng));
        ASSERT_TRUE(gl->upload(oneTriangle(a, b, d)));
        auto count = gl->countTrianglesInFrustum(view);
        ASSERT_TRUE(count) << count.error();
        auto stats = gl->render(view, img);
        ASSERT_TRUE(stats) << stats.error();
        // The clipper emits the clipped polygon as a fan: ≥ 1 triangle exactly when some part
        // of the input is inside. A triangle the CPU culled never reaches it, and must be
        // outside (culling is conservative).
        const bool submitted = stats->clipping_input_primitives == 1;
        const uint64_t survives = stats->clipping_output_primitives > 0 ? 1 : 0;
        EXPECT_EQ(*count, survives) << "triangle " << i;
        (survives ? inside : outside)++;
        if (submitted && !survives)
            ++clipped_away;
    }
    std::printf("%d inside, %d outside of which %d passed CPU culling and were clipped away\n",
                inside, outside, clipped_away);
    EXPECT_GT(clipped_away, 5);
    EXPECT_GT(inside, 20);
    EXPECT_GT(outside, 20);
}

TEST(TriangleCount, RoomCountsTheQuadsTheViewReaches) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const Scene room = test::texturedRoom();
    ASSERT_TRUE(gl->upload(room));
    const HmdProfile profile = test::smallProfile();
    // Looking ahead every quad but the wall behind intersects the view; the wall behind lies
    // wholly at z = +2, behind the eye.
    auto ahead = gl->countTrianglesInFrustum(fullFrameView(profile, Pose{}, Eye::kLeft));
    ASSERT_TRUE(ahead) << ahead.error();
    EXPECT_EQ(*ahead, room.triangleCount() - 2);
    // A narrow layer straight at the box's front face sees the box, the back wall and the floor
    // behind it, never the side walls or the ceiling.
    LayerRect l;
    l.rect = {150, 230, 170, 250};
    l.scale = 1.0;
    l.width_px = l.height_px = 20;
    auto narrow = gl->countTrianglesInFrustum(layerView(profile, Pose{}, Eye::kLeft, l));
    ASSERT_TRUE(narrow);
    EXPECT_LT(*narrow, *ahead);
    EXPECT_GE(*narrow, 2u);
}

#if defined(QVR_RENDER_HAVE_SCENE_LIBRARY)

// GL and CPU may disagree on a triangle that touches a frustum plane to within float rounding
// (GL clips in float clip space, the BVH in double world space). Such grazing triangles are
// rare: the bound is 0.05 % of the count, at least 3 triangles.
uint64_t countTolerance(uint64_t count) {
    return std::max<uint64_t>(3, count / 2000);
}

// Every view of a frame — full frame and the three layers of a plan, both eyes — from each
// head pose: GL's count of the triangles the view processes against the CPU BVH's.
void compareWithCpu(GlRenderer* gl, const Scene& scene, const std::vector<Pose>& poses) {
    ASSERT_TRUE(gl->upload(scene));
    auto null_renderer = makeNullRenderer();
    ASSERT_TRUE(null_renderer->upload(scene));
    ImageRgba8 img;
    uint64_t submitted_total = 0;
    const TriangleBvh bvh(scene);
    const HmdProfile profile = defaultHmdProfile();
    const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 15.0);
    uint64_t gl_total = 0, cpu_total = 0, max_diff = 0;
    int views = 0;
    for (const Pose& head : poses) {
        for (Eye eye : {Eye::kLeft, Eye::kRight}) {
            std::vector<std::pair<const char*, LayerRect>> layers;
            LayerRect full;
            full.rect = {0, 0, profile.width_px, profile.height_px};
            full.width_px = profile.width_px;
            full.height_px = profile.height_px;
            layers.emplace_back("full", full);
            for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter})
                layers.emplace_back(layerName(kind),
                                    layerOf(plan.eyes[static_cast<size_t>(eye)], kind));
            uint64_t full_count = 0;
            for (const auto& [name, layer] : layers) {
                auto g = gl->countTrianglesInFrustum(layerView(profile, head, eye, layer));
                ASSERT_TRUE(g) << g.error();
                const EyeView ev = eyeViewOf(profile, head, eye, layer);
                const uint64_t c = bvh.countTrianglesInFrustum(ev);
                const uint64_t diff = *g > c ? *g - c : c - *g;
                // Cluster culling is conservative: it submits at least what the view reaches.
                auto submitted = null_renderer->render(layerView(profile, head, eye, layer), img);
                ASSERT_TRUE(submitted);
                EXPECT_GE(submitted->primitives_generated, c) << name << " " << eyeName(eye);
                submitted_total += submitted->primitives_generated;
                EXPECT_LE(diff, countTolerance(c))
                    << name << " " << eyeName(eye) << ": GL " << *g << ", CPU " << c;
                gl_total += *g;
                cpu_total += c;
                max_diff = std::max(max_diff, diff);
                ++views;
                if (std::string(name) == "full")
                    full_count = c;
            }
            // The fovea cone (gaze on the axis, the camera's depth range) lies inside the fovea
            // layer's frustum, and the rings of the full view add up to its frustum count.
            const EyeView ev = fullFrameEyeView(profile, head, eye);
            ViewCone cone;
            cone.apex_m = ev.position_m;
            cone.direction = ev.orientation * glm::dvec3(0, 0, -1);
            cone.half_angle_deg = plan.e1_deg;
            cone.near_m = ev.near_m;
            cone.far_m = ev.far_m;
            const uint64_t in_cone = bvh.countTrianglesInCone(cone);
            auto fovea = gl->countTrianglesInFrustum(
                layerView(profile, head, eye, plan.eyes[static_cast<size_t>(eye)].fovea));
            ASSERT_TRUE(fovea);
            EXPECT_LE(in_cone, *fovea + countTolerance(*fovea));
            uint64_t ring_sum = 0;
            for (uint64_t n : bvh.trianglesPerRing(ev, glm::dvec3(0, 0, -1), 5.0, 18))
                ring_sum += n;
            EXPECT_EQ(ring_sum, full_count);
        }
    }
    std::printf(
        "%s: %d views, GL %llu vs CPU %llu triangles in all, largest difference %llu; "
        "%llu submitted after cluster culling\n",
        scene.name.c_str(), views, static_cast<unsigned long long>(gl_total),
        static_cast<unsigned long long>(cpu_total), static_cast<unsigned long long>(max_diff),
        static_cast<unsigned long long>(submitted_total));
    EXPECT_GT(cpu_total, 0u);
}

std::vector<Pose> spawnPoses(const Scene& scene, size_t max_spawns) {
    std::vector<Pose> poses;
    for (size_t i = 0; i < scene.spawns.size() && i < max_spawns; ++i) {
        for (double extra_yaw : {0.0, 120.0, 240.0}) {
            SpawnPoint s = scene.spawns[i];
            s.yaw_deg += static_cast<float>(extra_yaw);
            poses.push_back(poseFromSpawn(s));
        }
    }
    return poses;
}

TEST(TriangleCount, GlQueryMatchesTheCpuBvhCountOnTheBuiltinRoom) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    auto scene = loadScene("builtin:room?objects=8");
    ASSERT_TRUE(scene) << scene.error();
    std::vector<Pose> poses = spawnPoses(*scene, 1);
    Pose tilted;
    tilted.orientation = quatFromEulerDeg({30.0, -25.0, 10.0});
    tilted.position_m = {0.5f, 1.6f, 1.0f};
    poses.push_back(tilted);
    compareWithCpu(gl, *scene, poses);
}

TEST(TriangleCount, GlQueryMatchesTheCpuBvhCountOnOpenArenaDm5) {
    QVR_GL_RENDERER_OR_SKIP(gl);
    const SceneLoadOptions defaults;
    if (!std::filesystem::exists(defaults.openarena_dir))
        GTEST_SKIP() << "OpenArena data not installed in " << defaults.openarena_dir
                     << " (Debian: openarena-081-maps openarena-081-textures openarena-data)";
    SceneLoadOptions opts;
    opts.load_textures = false;  // counting needs geometry only
    opts.load_lightmaps = false;
    auto scene = loadScene("openarena:oa_dm5", opts);
    ASSERT_TRUE(scene) << scene.error();
    compareWithCpu(gl, *scene, spawnPoses(*scene, 2));
}

#endif  // QVR_RENDER_HAVE_SCENE_LIBRARY

}  // namespace
}  // namespace qvr
