// The workload probe LIWC runs before every qvr frame on the headset thread (runtime
// WorkloadProbe): triangles per ring from the draw clusters, pixels per ring around the gaze, on
// the default run's scene (builtin:room, 32 objects) and profile (1920×2160 per eye).
#include <benchmark/benchmark.h>

#include <memory>

#include "qvr/core/pose.h"
#include "qvr/render/draw_list.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/workload_probe.h"
#include "qvr/scene/builtin_scene.h"

namespace {

using namespace qvr;

struct RoomProbe {
    Scene scene = makeBuiltinRoom(32);
    std::unique_ptr<runtime::WorkloadProbe> probe;
    Pose head;
    size_t cluster_count = 0;
    RoomProbe() {
        const HmdProfile profile = *runtime::runtimeProfileByName("default");
        auto clusters = std::make_shared<DrawList>(buildDrawList(scene));
        buildLods(*clusters, scene);
        cluster_count = clusters->clusters.size();
        probe = std::make_unique<runtime::WorkloadProbe>(profile, nullptr);
        probe->useClusters(clusters, 1.0f);
        const SpawnPoint sp = scene.spawns[0];
        head.position_m = sp.position_m;
        head.orientation = quatFromEulerDeg({sp.yaw_deg, -10.0, 0.0});
    }
};

const RoomProbe& roomProbe() {
    static const RoomProbe r;
    return r;
}

// A gaze that moves a little every frame, as the recorded ones do.
Gaze gazeAt(int64_t i) {
    return Gaze{double(i % 11) - 5.0, double(i % 7) - 3.0};
}

void BM_ProbeFrame(benchmark::State& state) {
    const RoomProbe& r = roomProbe();
    int64_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(r.probe->frame(i, 11.1 * double(i), r.head, gazeAt(i)));
        ++i;
    }
    state.counters["clusters"] = static_cast<double>(r.cluster_count);
}
BENCHMARK(BM_ProbeFrame)->Unit(benchmark::kMicrosecond);

void BM_ProbePixelsPerRing(benchmark::State& state) {
    const RoomProbe& r = roomProbe();
    int64_t i = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(r.probe->pixelsPerRing(gazeAt(i++)));
}
BENCHMARK(BM_ProbePixelsPerRing)->Unit(benchmark::kMicrosecond);

}  // namespace
