// One layer plan (Eq. 1): the e2* search dominates; the single cone bound is the unit it repeats.
#include <benchmark/benchmark.h>

#include "qvr/foveation/layer_plan.h"

namespace {

using namespace qvr;

void BM_LayerPlan(benchmark::State& state) {
    const LayerPlanner planner(defaultHmdProfile());
    const double e1 = static_cast<double>(state.range(0));
    double gx = 0.0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(planner.plan(Gaze{gx, -0.5 * gx}, e1));
        gx = gx > 20.0 ? 0.0 : gx + 0.37;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LayerPlan)->Arg(5)->Arg(15)->Arg(40)->Unit(benchmark::kMicrosecond);

void BM_ConeBounds(benchmark::State& state) {
    const EyeGeometry geometry(defaultHmdProfile());
    double e = 1.0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(geometry.coneBounds(Gaze{10.0, 5.0}, e));
        e = e > 60.0 ? 1.0 : e + 0.5;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ConeBounds);

}  // namespace
