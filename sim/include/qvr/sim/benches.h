// The benchmark suite the evaluation runs (paper Table 3): seven workloads recorded from
// OpenArena levels (data/workloads/, docs/RECORDING.md) or seven seeded synthetic stand-ins,
// or any recorded trace file.
#pragma once

#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/workload/workload.h"

namespace qvr {

struct BenchInfo {
    std::string name;   // "synthetic-…" or the recorded workload's name ("oa-dm5-h")
    std::string label;  // Table 3/4 column: D3H, D3L, … or DM5-H, …
};

// Which suite suiteBenches() lists. The library default is the synthetic one (tests and
// benchmarks do not depend on files); `qvr eval` selects the recorded one when it finds it.
enum class SuiteKind { kSynthetic, kRecorded };

// Selects the recorded suite in `dir` (its suite.txt, written by scripts/record_suite.sh) or
// the synthetic one. Checks that suite.txt exists and names readable traces; the traces
// themselves are read when a bench is made.
Status selectSuite(SuiteKind kind, const std::string& dir = "");
SuiteKind selectedSuite();
// The data/workloads folder of the source tree: searched upward from the working directory and
// from the running executable's folder; empty when not found.
std::string findWorkloadsDir();

// The selected suite in Table 3's order.
std::vector<BenchInfo> suiteBenches();
// A bench by name with `frames` frames: a synthetic one ("synthetic-doom3-h", or without the
// prefix) always, a recorded one when the recorded suite is selected. A recorded trace shorter
// than `frames` is replayed forwards and backwards (its poses stay continuous). `codec` picks the
// recorded codec setting of a recorded bench (docs/MODEL.md); a synthetic bench's bits per pixel
// already stand for the paper's (Table 1), so both settings give the same synthetic trace.
Expected<WorkloadTrace> makeSuiteBench(const std::string& name, int frames,
                                       CodecModel codec = CodecModel::kStream);
std::string suiteBenchNamesList();
// One sentence (HTML-safe) saying what the selected suite's workloads are, for reports.
std::string suiteDescription();

}  // namespace qvr
