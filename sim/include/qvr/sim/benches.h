// The benchmark suite the evaluation runs (paper Table 3): seven seeded synthetic workloads
// standing in for the games until recorded traces exist, or any recorded trace file.
#pragma once

#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/workload/workload.h"

namespace qvr {

struct BenchInfo {
    std::string name;   // "synthetic-…" as the suite names it
    std::string label;  // Table 3/4 column: D3H, D3L, H2H, H2L, GD, UT3, WF
};

// The default suite in Table 3's order.
std::vector<BenchInfo> suiteBenches();
// A synthetic bench by name ("synthetic-doom3-h", or without the "synthetic-" prefix), with
// `frames` frames.
Expected<WorkloadTrace> makeSuiteBench(const std::string& name, int frames);
std::string suiteBenchNamesList();

}  // namespace qvr
