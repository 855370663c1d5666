// The two cores at once. In a run the headset and the server work at the same time, each on its
// core and in its own process; on a machine whose cores share memory bandwidth, a physical core
// or a host's time, each is then slower than alone, which no part timed alone shows. How much
// depends on what both do: a rasteriser beside a rasteriser can measure x1.00 where a run's
// layers take 1.15x their law, a streaming copy beside another 2.2x (docs/MODEL.md
// §8 "Co-running"). So each side's frames (SideMix) are timed on this core alone and beside
// `qvr corun-load` doing the other side's frames on another core without pause: pairs of
// blocks, alone then shared, over the same frames. A process, not a thread: llvmpipe serialises
// the rasterisation of contexts that share its screen.
#include <array>
#include <string>
#include <vector>

#include "calibration_bench.h"
#include "calibration_side_mix.h"
#include "corun_load.h"
#include "qvr/runtime/affinity.h"

namespace qvr::experiment {

namespace {

constexpr int kBlock = 6;  // frames in a row, alone or shared

// `pairs` pairs of blocks of `self`'s frames, alone then beside the load. A load that stops
// answering ends the pairs early, with load_error set.
Expected<CoRunPairs> timePairs(CoRunLoad& load, SideMix& side, bool headset_side, int pairs,
                               std::string& load_error) {
    const char* self = headset_side ? "headset" : "server";
    auto frame = [&](int step) { return headset_side ? side.headset(step) : side.server(step); };
    CoRunPairs out;
    for (int pair = 0; pair < pairs; ++pair) {
        std::array<std::vector<double>, 2> ms;
        for (int with = 0; with < 2; ++with) {
            if (auto st = load.setBusy(with == 1); !st) {
                load_error = st.error();
                return out;
            }
            for (int k = 0; k < kBlock; ++k) {
                const auto t0 = CalibrationClock::now();
                if (auto st = frame(1 + pair * kBlock + k); !st)
                    return makeError(std::string("co-run ") + self + " frame: " + st.error());
                ms[static_cast<size_t>(with)].push_back(msSince(t0));
            }
        }
        out.alone_ms.insert(out.alone_ms.end(), ms[0].begin(), ms[0].end());
        out.shared_ms.insert(out.shared_ms.end(), ms[1].begin(), ms[1].end());
    }
    return out;
}

// One side's slowdown beside the other's frames on core `other` (< 0: there is none).
Expected<Calibration::CoRun> measureSide(const CalibrationBench& bench, SideMix& side,
                                         bool headset_side, int other) {
    const char* self = headset_side ? "headset" : "server";
    const char* load_mix = headset_side ? "server" : "headset";
    Calibration::CoRun out;
    if (other < 0) {
        out.note = "one core: no co-running to measure";
        return out;
    }
    auto load = CoRunLoad::start(bench.options, other, load_mix);
    if (!load) {  // a load that cannot run leaves co-running unmeasured (x1)
        out.note = "not measured: " + load.error();
        return out;
    }
    if (auto st = headset_side ? side.headset(0) : side.server(0); !st)  // warm-up
        return makeError(std::string("co-run ") + self + " frame: " + st.error());
    std::string load_error;
    auto pairs = timePairs(**load, side, headset_side, bench.options.quick ? 6 : 10, load_error);
    (*load)->stop();
    if (!pairs)
        return makeError(pairs.error());
    if (!load_error.empty() || pairs->alone_ms.empty()) {
        out.note = "not measured: the load process: " + load_error;
        return out;
    }
    return fitCoRun(*pairs, self, other, load_mix);
}

}  // namespace

Status measureCoRun(CalibrationBench& bench, Calibration& cal) {
    const int cores = runtime::onlineCores();
    const int other = cores > 1 ? (bench.options.core == cores - 1 ? 0 : cores - 1) : -1;
    SideMix side(bench.r(), bench.profile, bench.inputs, bench.codec);
    auto headset = measureSide(bench, side, true, other);
    if (!headset)
        return makeError(headset.error());
    cal.corun_headset = *headset;
    bench.log("  co-running, headset: " + cal.corun_headset.note + "\n");
    auto server = measureSide(bench, side, false, other);
    if (!server)
        return makeError(server.error());
    cal.corun_server = *server;
    bench.log("  co-running, server: " + cal.corun_server.note + "\n");
    // Measured per side; the shared factor stays 1 (sim/hardware.h).
    cal.costs.corun_headset_slowdown = cal.corun_headset.slowdown;
    cal.costs.corun_server_slowdown = cal.corun_server.slowdown;
    return {};
}

}  // namespace qvr::experiment
