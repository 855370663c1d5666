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

// The runtime's LIWC (docs/LIWC.md "The runtime's objective"): the pipelined period over the
// window and the far grid, its fits refitted every frame; arg 1: told a CPU quota of 0.6.
void BM_LiwcPeriodDecideAndUpdate(benchmark::State& state) {
    Fixture& fx = fixture();
    LiwcConfig c;
    c.learn_remote_base = true;
    c.frame_period_objective = true;
    c.frames_in_flight = 2;
    LiwcPolicy liwc(fx.trace.header, c);
    if (state.range(0) != 0)
        liwc.setHeadsetShare(0.6);
    size_t i = 0;
    for (auto _ : state) {
        const WorkloadFrame& f = fx.trace.frames[i];
        liwc.setLinkEstimate(fx.truth.throughputBps());
        const Decision d = liwc.decide(f);
        benchmark::DoNotOptimize(d);
        FrameMeasurement m = fx.measurements[i];
        m.e1_deg = d.e1_deg;
        m.t_render_ms = 0.5 * m.t_local_ms;
        m.t_decode_ms = 0.5;
        m.server_ms = 0.5 * m.t_remote_ms;
        liwc.observe(m);
        i = (i + 1) % fx.trace.frames.size();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LiwcPeriodDecideAndUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

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
