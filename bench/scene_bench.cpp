// The triangle BVH's queries against brute force on a ~2 M-triangle room: the fovea cone and the
// 18 rings the workload recorder asks for each frame.
#include <benchmark/benchmark.h>

#include <glm/gtc/quaternion.hpp>

#include "qvr/core/pose.h"
#include "qvr/scene/builtin_scene.h"
#include "qvr/scene/triangle_bvh.h"

namespace {

using namespace qvr;

struct LargeRoom {
    Scene scene = makeBuiltinRoom(400);
    TriangleBvh bvh{scene};
    EyeView view;
    ViewCone fovea;
    LargeRoom() {
        const SpawnPoint sp = scene.spawns[0];
        view = EyeView::symmetric(glm::dvec3(sp.position_m),
                                  glm::dquat(quatFromEulerDeg({sp.yaw_deg, -25.0, 0.0})), 100, 110,
                                  0.05, 100);
        fovea = ViewCone{glm::dvec3(sp.position_m), view.orientation * glm::dvec3(0, 0, -1), 10.0,
                         0.05, 100};
    }
};

const LargeRoom& largeRoom() {
    static const LargeRoom room;
    return room;
}

void BM_BvhConeAndRings(benchmark::State& state) {
    const LargeRoom& r = largeRoom();
    for (auto _ : state) {
        benchmark::DoNotOptimize(r.bvh.countTrianglesInCone(r.fovea));
        benchmark::DoNotOptimize(r.bvh.trianglesPerRing(r.view, {0, 0, -1}, 5.0, 18));
    }
    state.counters["triangles"] = static_cast<double>(r.scene.triangleCount());
}
BENCHMARK(BM_BvhConeAndRings)->Unit(benchmark::kMillisecond);

void BM_BruteForceConeAndRings(benchmark::State& state) {
    const LargeRoom& r = largeRoom();
    for (auto _ : state) {
        benchmark::DoNotOptimize(r.bvh.countTrianglesInConeBruteForce(r.fovea));
        benchmark::DoNotOptimize(r.bvh.trianglesPerRingBruteForce(r.view, {0, 0, -1}, 5.0, 18));
    }
    state.counters["triangles"] = static_cast<double>(r.scene.triangleCount());
}
BENCHMARK(BM_BruteForceConeAndRings)->Unit(benchmark::kMillisecond);

}  // namespace
