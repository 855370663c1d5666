// `qvr control` as a typed function: a plan in (the workload, the link, the GPU clock, the
// policy), a report out (the policy's run beside the oracle's, and every other policy's when
// compared), and the report as text or JSON (paper §4.1, §6.2).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "qvr/controller/control_run.h"
#include "qvr/core/expected.h"

namespace qvr {

// The policies `--compare` runs, in the order they are reported.
inline constexpr const char* kComparedPolicies[] = {"liwc", "sw", "fixed", "oracle"};

// The workload: a trace file when `trace_path` is given, else the synthetic suite's `bench` (the
// default synthetic workload when empty) with `frames` frames. Errors name the file or list
// the suite.
Expected<WorkloadTrace> controlWorkload(const std::string& trace_path, const std::string& bench,
                                        int frames);

// The effective link throughput of a profile (wifi, lte, 5g): its nominal rate times the Table 1
// link efficiency (core/link_efficiency.h), in Mbit/s.
Expected<double> effectiveThroughputMbps(const std::string& net);

struct ControlPlan {
    std::string policy = "liwc";
    int frames = 300;
    double throughput_mbps = 0.0;
    double gpu_mhz = 500.0;
    double fixed_e1_deg = 5.0;
    bool compare = false;  // also run every policy of kComparedPolicies
};

struct ControlReport {
    ControlPlan plan;
    WorkloadHeader workload;
    size_t workload_frames = 0;
    ControlRun run;         // the plan's policy
    ControlSummary oracle;  // the yardstick every policy is measured against
    std::vector<std::pair<std::string, ControlSummary>> compared;  // with plan.compare
    double local_only_ms_mean = 0.0;  // rendering the run's frames locally
};

// Runs the plan's policy (and the oracle, and with compare every policy) over the trace under
// the ground-truth cost model; an error for an unknown policy.
Expected<ControlReport> runControl(const WorkloadTrace& trace, const ControlPlan& plan);

// The report as `qvr control` prints it: a table of every 20th frame and a summary line per
// policy; and as `--json` prints it (per-frame records, summary, comparison).
std::string controlReportText(const ControlReport& report);
std::string controlReportJson(const ControlReport& report);

}  // namespace qvr
