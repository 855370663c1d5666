// Throughput of the pipeline simulator (paper §5): frames simulated per second for each design
// on one synthetic workload, and the GPU timeline's render scheduling under many passes.
#include <benchmark/benchmark.h>

#include <limits>

#include "qvr/sim/benches.h"
#include "qvr/sim/gpu_timeline.h"
#include "qvr/sim/simulator.h"

namespace {

const qvr::WorkloadTrace& trace() {
    static const qvr::WorkloadTrace t = *qvr::makeSuiteBench("synthetic-ut3", 300);
    return t;
}

void BM_SimulateDesign(benchmark::State& state) {
    const auto design = static_cast<qvr::Design>(state.range(0));
    qvr::SimConfig cfg;
    cfg.design = design;
    cfg.frames = 300;
    for (auto _ : state) {
        qvr::NoisyLink link("wifi", 200e6, qvr::calibratedLinkEfficiency(), 20.0, {}, 1);
        auto run = qvr::simulate(trace(), cfg, link);
        benchmark::DoNotOptimize(run.summary.mtp_ms_mean);
    }
    state.SetItemsProcessed(state.iterations() * cfg.frames);
    state.SetLabel(std::string(qvr::traitsOf(design).name));
}
BENCHMARK(BM_SimulateDesign)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

void BM_GpuTimelineRenderAmongPasses(benchmark::State& state) {
    for (auto _ : state) {
        qvr::GpuTimeline gpu;
        double t = 0.0;
        for (int i = 0; i < 1000; ++i) {
            gpu.runPass(t + 1.5, 0.5);
            const auto slot = gpu.runRender(t, 3.0, 0.05);
            t = slot.end_ms;
        }
        benchmark::DoNotOptimize(t);
    }
    state.SetItemsProcessed(state.iterations() * 1000);
}
BENCHMARK(BM_GpuTimelineRenderAmongPasses);

}  // namespace
