// One LIWC decision + update (paper §4.3 claims nanoseconds in hardware), against the oracle's
// exhaustive search on the same frames as the baseline in the same run.
#include <benchmark/benchmark.h>

#include "qvr/controller/liwc.h"
#include "qvr/core/link_efficiency.h"
#include "qvr/workload/synthetic.h"

namespace {

using namespace qvr;

struct Fixture {
    WorkloadTrace trace;
    CostModel truth;
    std::vector<FrameMeasurement> measurements;

    Fixture()
        : trace([] {
              SyntheticSpec spec = defaultSyntheticSpec();
              spec.frames = 256;
              return generateSyntheticWorkload(spec);
          }()),
          truth(trace.header, GpuModel{}, 200e6 * calibratedLinkEfficiency()) {
        // Pre-compute each frame's measurement at 12° so the benchmark times only LIWC.
        for (const auto& f : trace.frames) {
            const LayerPlan plan = truth.planner().plan(f.gaze, 12.0);
            const FrameCost c = truth.cost(f, plan);
            measurements.push_back(measureFrame(f.index, plan, c, truth.throughputBps()));
        }
    }
};

Fixture& fixture() {
    static Fixture f;
    return f;
}

void BM_LiwcDecideAndUpdate(benchmark::State& state) {
    Fixture& fx = fixture();
    LiwcPolicy liwc(fx.trace.header);
    size_t i = 0;
    for (auto _ : state) {
        const WorkloadFrame& f = fx.trace.frames[i];
        const Decision d = liwc.decide(f);
        benchmark::DoNotOptimize(d);
        FrameMeasurement m = fx.measurements[i];
        m.e1_deg = d.e1_deg;
        liwc.observe(m);
        i = (i + 1) % fx.trace.frames.size();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LiwcDecideAndUpdate);

void BM_OracleDecide(benchmark::State& state) {
    Fixture& fx = fixture();
    auto oracle = makeOraclePolicy(fx.trace.header, fx.truth);
    size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(oracle->decide(fx.trace.frames[i]));
        i = (i + 1) % fx.trace.frames.size();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_OracleDecide)->Unit(benchmark::kMicrosecond);

void BM_LiwcConstruct(benchmark::State& state) {
    Fixture& fx = fixture();
    for (auto _ : state) {
        LiwcPolicy liwc(fx.trace.header);
        benchmark::DoNotOptimize(&liwc);
    }
}
BENCHMARK(BM_LiwcConstruct)->Unit(benchmark::kMillisecond);

}  // namespace
