// `qvr sim` as typed functions: one design over one workload on the paper's pipeline (§5) or the
// model of the runtime's pipeline (runtime_model.h) — its inputs resolved from their names, its
// frames.csv and summary.json written, and the lines it prints.
#pragma once

#include <filesystem>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/runtime_model.h"
#include "qvr/sim/simulator.h"
#include "qvr/workload/workload.h"

namespace qvr {

// The workload: the synthetic suite's `bench` with `frames` frames, or the trace file at
// `trace_path` (exactly one of them non-empty); its periphery bytes from `codec_model` ("auto":
// lossless when the trace recorded it, the paper's setting, else stream). An error when it
// cannot be had or has no frames.
Expected<WorkloadTrace> simWorkload(const std::string& bench, const std::string& trace_path,
                                    int frames, const std::string& codec_model);

// The modelled hardware at `gpu_mhz`: the defaults, or the TOML file at `path` when given.
Expected<HardwareConfig> simHardware(const std::string& path, double gpu_mhz);

// The paper pipeline's run: frames.csv and summary.json in `out` (made when missing).
Status writeSimRunOutputs(const std::filesystem::path& out, const RunResult& run);
std::string simRunReport(const RunSummary& s, const std::string& out);

// The runtime pipeline's run: frames.csv and summary.json of its own in `out`.
struct RuntimeSimSetting {
    std::string net;  // a link spec (makeRuntimeLink)
    int pipeline_depth = 2;
    double wait_limit_ms = 250.0;
    int frames = 300;
};
// The runtime pipeline over `trace` with the hardware file's calibrated costs, the link's delay
// added to theirs; an error for the static design (the runtime has none) or a bad link.
Expected<RuntimeRunResult> simulateRuntimePipeline(const WorkloadTrace& trace, Design design,
                                                   const HardwareConfig& hw,
                                                   const RuntimeSimSetting& setting);
Status writeRuntimeSimOutputs(const std::filesystem::path& out, const RuntimeRunResult& run,
                              const RuntimeSimSetting& setting);
std::string runtimeSimReport(const RuntimeSummary& s, const std::string& bench,
                             const RuntimeSimSetting& setting, const std::string& out);

}  // namespace qvr
