// Google Benchmark kernels of UCA (paper §4.2, Eq. 3–4): one frame of both 1920×2160 eyes with
// e1 = 15° and a 2.3° pose change, through UCA, its scalar twin, the two-pass reference and (when
// built) the OpenCV anchor; items are display pixels, bytes are UCA's reads + writes.
#include <array>
#include <cstring>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "qvr/compose/opencv_two_pass.h"
#include "qvr/compose/test_pattern.h"
#include "qvr/compose/uca.h"
#include "qvr/foveation/layer_plan.h"

namespace {

using namespace qvr;

struct Scene {
    HmdProfile profile = defaultHmdProfile();
    LayerFrame frame;
    Pose display;
    double bytes = 0.0;

    Scene() {
        const LayerPlan plan = LayerPlanner(profile).plan({0.0, 0.0}, 15.0);
        frame = makeTestPatternFrame(profile, plan, Pose{}, 1,
                                     renderTestPattern(profile.width_px, profile.height_px));
        display.orientation = quatFromEulerDeg({2.0, 1.0, 0.5});
        for (const auto& e : frame.eyes) {
            bytes += static_cast<double>(e.fovea.sizeBytes() + e.middle.sizeBytes() +
                                         e.outer.sizeBytes());
        }
        bytes += 2.0 * 4.0 * profile.width_px * profile.height_px;
    }
};

const Scene& scene() {
    static const Scene s;
    return s;
}

void report(benchmark::State& state, const Scene& s) {
    const double pixels = 2.0 * s.profile.width_px * s.profile.height_px;
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * pixels));
    state.SetBytesProcessed(
        static_cast<int64_t>(static_cast<double>(state.iterations()) * s.bytes));
}

void BM_Uca(benchmark::State& state) {
    const Scene& s = scene();
    ComposeOptions o;
    o.threads = static_cast<int>(state.range(0));
    o.simd = state.range(1) != 0;
    o.mesh_map = state.range(2) != 0;
    Compositor c(s.profile, o);
    std::array<ImageRgba8, 2> out;
    TileStats tiles;
    for (auto _ : state) {
        auto r = c.compose(s.frame, s.display, out);
        benchmark::DoNotOptimize(out[0].data());
        if (!r) {
            state.SkipWithError(r.error().c_str());
            break;
        }
        tiles = r->tiles;
    }
    report(state, s);
    state.counters["single_tiles"] = static_cast<double>(tiles.single);
    state.counters["mesh_tiles"] = static_cast<double>(tiles.mesh);
}
BENCHMARK(BM_Uca)
    ->ArgNames({"threads", "simd", "mesh"})
    ->Args({1, 1, 1})
    ->Args({1, 1, 0})
    ->Args({2, 1, 1})
    ->Args({2, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The two-pass baselines' common loop: a Composer made from the profile and the thread count,
// then `pass(composer, scene, out)` once an iteration, which reports a status.
template <typename Composer, typename Pass>
void benchTwoPass(benchmark::State& state, Pass pass) {
    const Scene& s = scene();
    ComposeOptions o;
    o.threads = static_cast<int>(state.range(0));
    Composer composer(s.profile, o);
    std::array<ImageRgba8, 2> out;
    for (auto _ : state) {
        const auto status = pass(composer, s, out);
        benchmark::DoNotOptimize(out[0].data());
        if (!status)
            state.SkipWithError(status.error().c_str());
    }
    report(state, s);
}

// One and two threads, in milliseconds of wall-clock time.
void threadCounts(benchmark::internal::Benchmark* b) {
    b->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
}

void BM_TwoPass(benchmark::State& state) {
    benchTwoPass<Compositor>(state, [](Compositor& c, const Scene& s, auto& out) {
        return c.composeTwoPass(s.frame, s.display, out);
    });
}
BENCHMARK(BM_TwoPass)->Apply(threadCounts);

// The bandwidth floor's yardstick: a copy far larger than the caches on one thread; bytes are
// read + written, so UCA's floor is its bytes divided by this rate.
void BM_CopyBandwidth(benchmark::State& state) {
    const size_t bytes = size_t{256} << 20;
    std::vector<uint8_t> src(bytes, 1), dst(bytes, 0);
    for (auto _ : state) {
        std::memcpy(dst.data(), src.data(), bytes);
        benchmark::DoNotOptimize(dst.data());
        benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * 2 *
                            static_cast<int64_t>(bytes));
}
BENCHMARK(BM_CopyBandwidth)->Unit(benchmark::kMillisecond);

#if defined(QVR_COMPOSE_HAVE_OPENCV)
void BM_OpenCvTwoPass(benchmark::State& state) {
    benchTwoPass<OpenCvTwoPass>(state, [](OpenCvTwoPass& anchor, const Scene& s, auto& out) {
        return anchor.run(s.frame, s.display, out);
    });
}
BENCHMARK(BM_OpenCvTwoPass)->Apply(threadCounts);
#endif

}  // namespace
