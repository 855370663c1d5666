// The Table 3 suite by name, from the workload part's synthetic generator.
#include "qvr/sim/benches.h"

#include <array>

#include <fmt/format.h>

#include "qvr/workload/synthetic.h"

namespace qvr {

namespace {

// paperSyntheticSuite() lists Table 3's rows in order; these are Table 4's column labels.
constexpr std::array<const char*, 7> kLabels = {"D3H", "D3L", "H2H", "H2L", "GD", "UT3", "WF"};

}  // namespace

std::vector<BenchInfo> suiteBenches() {
    std::vector<BenchInfo> out;
    const auto suite = paperSyntheticSuite();
    for (size_t i = 0; i < suite.size(); ++i)
        out.push_back({suite[i].name, i < kLabels.size() ? kLabels[i] : suite[i].name});
    return out;
}

std::string suiteBenchNamesList() {
    std::string s;
    for (const auto& b : suiteBenches()) {
        if (!s.empty())
            s += ", ";
        s += b.name;
    }
    return s;
}

Expected<WorkloadTrace> makeSuiteBench(const std::string& name, int frames) {
    if (frames <= 0 || frames > 1'000'000)
        return makeError(fmt::format("frames must be in 1..1000000, got {}", frames));
    for (SyntheticSpec spec : paperSyntheticSuite()) {
        if (spec.name == name || spec.name == "synthetic-" + name) {
            spec.frames = frames;
            return generateSyntheticWorkload(spec);
        }
    }
    return makeError(fmt::format("unknown bench '{}': expected one of {} (or --trace FILE)", name,
                                 suiteBenchNamesList()));
}

}  // namespace qvr
