// Capacity planning: how many headsets one render server carries at a target frame rate, from
// the calibrated runtime model (runtime_model.h). The server renders on one thread, so with N
// headsets each headset's frame waits on the other N − 1 headsets' frames: the model runs one
// headset with the server's costs N times its own (RuntimeCosts::atSpeed) — exact when the server
// is the bottleneck (it then serves each headset 1/N of its time), pessimistic for latency when
// it is idle part of the time. The headset's own costs grow by its share of a core: 1/share on a
// device of its own, and on a machine where the N headsets share one core (qvr run --headsets N
// on two cores) by max(1/share, N).
#pragma once

#include <string>
#include <vector>

#include "qvr/core/design.h"
#include "qvr/core/expected.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/runtime_model.h"
#include "qvr/workload/workload.h"

namespace qvr {

struct CapacityOptions {
    Design design = Design::Qvr;
    double fixed_e1_deg = 5.0;
    double target_fps = 60.0;
    int max_headsets = 16;
    std::string net = "wifi";  // each headset's link (makeRuntimeLink)
    double headset_share = 1.0;
    bool headsets_share_one_core = false;
    int pipeline_depth = 2;
    double wait_limit_ms = 250.0;
    int frames = 300;
    int warmup_frames = 10;
    bool every_count = false;  // predict every count up to max_headsets (else stop below target)
    // The machine's speed over the calibration's: its times are the calibrated ones times these
    // (a run's speed probes measure them: summary.json calibration.speed_reference
    // .run_over_reference). On top of the headset count's factors.
    SideFactors speed;
};

// The factors on the headset's and the server's times with `headsets` headsets.
SideFactors capacityFactors(int headsets, double headset_share, bool share_one_core);

// One headset count's prediction.
struct CapacityPoint {
    int headsets = 0;
    SideFactors factors;
    RuntimeSummary summary;  // one headset's (every headset alike)
    // The server's busy time over its time: N × its time per served frame × FPS.
    double server_utilisation = 0.0;
};

struct CapacityResult {
    std::vector<CapacityPoint> points;  // 1 … max_headsets, or up to the first below the target
    int headsets = 0;                   // the most with every headset at the target (0: none)
};

// The largest headset count whose point reaches the target FPS (counts from 1 in order: the first
// point below the target ends the count).
int headsetsAtTarget(const std::vector<CapacityPoint>& points, double target_fps);

// The triangles each layer draws at frame k (RuntimeSimConfig::layer_triangles); empty: the
// trace's ring counts.
using CapacityLayerTriangles = decltype(RuntimeSimConfig::layer_triangles);

// Every headset count from 1 to max_headsets predicted on `trace` with `costs` (a calibration's
// [runtime]); stops after the first two counts below the target unless every_count.
Expected<CapacityResult> predictCapacity(const WorkloadTrace& trace, const RuntimeCosts& costs,
                                         const CapacityOptions& options,
                                         const CapacityLayerTriangles& layer_triangles = {});

// The calibration file (qvr calibrate --out; its [runtime] pipeline) and the workload trace file
// (a qvr run's workload.jsonl, data/workloads/*.jsonl) predictCapacity takes.
struct CapacityInputs {
    WorkloadTrace trace;
    RuntimeCosts costs;
};
Expected<CapacityInputs> loadCapacityInputs(const std::string& hardware_path,
                                            const std::string& trace_path);

// The result for the console: a line per count and the count at the target.
std::string capacityText(const CapacityResult& result, const CapacityOptions& options);
// The result as JSON text: the options, every point and the count at the target.
std::string capacityJson(const CapacityResult& result, const CapacityOptions& options);

}  // namespace qvr
