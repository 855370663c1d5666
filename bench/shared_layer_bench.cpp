// Shared periphery: what handing a group's render to a member costs the server (the reuse path
// of docs/RUNTIME.md §Shared periphery), against rendering the member's own layer.
#include <benchmark/benchmark.h>
#include <glm/gtc/quaternion.hpp>

#include "qvr/compose/bilinear_span.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/shared_periphery.h"

namespace {

using namespace qvr;

// The small display's layer `kind` for e1 = 10°, and the group's render of it (margin 3°).
struct Case {
    HmdProfile profile = runtime::runtimeProfileByName("small").value();
    LayerPlan plan;
    runtime::SharedLayer shared;
    ImageRgba8 image;
    explicit Case(LayerKind kind) {
        plan = LayerPlanner(profile).plan({0.0, 0.0}, 10.0);
        shared = runtime::sharedLayerPlan(profile, {plan}, Eye::kLeft, kind, {}, 3.0);
        const LayerRect& r = layerOf(shared.plan.eyes[0], kind);
        image.resize(r.width_px, r.height_px);
        for (int j = 0; j < r.height_px; ++j)
            for (int i = 0; i < r.width_px; ++i)
                for (int c = 0; c < 4; ++c)
                    image.at(i, j, c) = static_cast<uint8_t>((i * 7 + j * 13 + c * 29) & 255);
    }
};

// Arg 0: the middle layer, 1: the outer; yaw between the render and the member, in 1/10 degree.
void BM_ReduceSharedLayer(benchmark::State& state) {
    const LayerKind kind = state.range(0) == 0 ? LayerKind::kMiddle : LayerKind::kOuter;
    const Case c(kind);
    const glm::quat a = quatFromEulerDeg({0.0, 0.0, 0.0});
    const glm::quat b = quatFromEulerDeg({double(state.range(1)) / 10.0, 0.0, 0.0});
    const LayerRect& mine = layerOf(c.plan.eyes[0], kind);
    ImageRgba8 out;
    for (auto _ : state) {
        runtime::reduceSharedLayer(c.image, layerOf(c.shared.plan.eyes[0], kind), mine, out,
                                   c.profile, a, b);
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["texels"] = double(mine.pixels());
}
BENCHMARK(BM_ReduceSharedLayer)
    ->Args({0, 0})
    ->Args({0, 5})
    ->Args({1, 0})
    ->Args({1, 5})
    ->Unit(benchmark::kMicrosecond);

// The warp's taps alone, the vector kernel (arg 1) against its scalar twin (arg 0): the outer
// layer's texels as 5° of yaw lays them on the render, 16 to a span.
void BM_BilinearSpans(benchmark::State& state) {
    const Case c(LayerKind::kOuter);
    const LayerRect& mine = layerOf(c.plan.eyes[0], LayerKind::kOuter);
    std::vector<FixedSpan> spans;
    for (int j = 0; j < mine.height_px; ++j)
        for (int i = 0; i < mine.width_px; i += 16)
            spans.push_back({int64_t(i) * 65536 + 40000, int64_t(j) * 65536 + 9000 * (i / 16),
                             63000, 700, std::min(16, mine.width_px - i)});
    std::vector<uint8_t> out(size_t(mine.pixels()) * 4);
    for (auto _ : state) {
        if (state.range(0) == 1)
            bilinearSpans(c.image, spans.data(), spans.size(), out.data());
        else
            bilinearSpansScalar(c.image, spans.data(), spans.size(), out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.counters["texels"] = double(mine.pixels());
    state.SetLabel(state.range(0) == 1 ? bilinearSpanTarget() : "scalar");
}
BENCHMARK(BM_BilinearSpans)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
