// The paper's qualitative findings (§6.1, §6.3) as properties of the simulator on the
// synthetic Table 3 suite. Where the paper's finding is checked per benchmark but ours holds
// only on average, the test says so and the report explains it.
#include <gtest/gtest.h>

#include <map>
#include <thread>

#include "qvr/sim/benches.h"
#include "qvr/sim/simulator.h"

namespace qvr {
namespace {

// Unoptimised and sanitised builds run LIWC ~25x slower; they check the same properties on
// two of the seven benches (the light low-resolution one and the heaviest) so ctest's per-test
// timeout holds there too. Optimised builds check all seven.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__OPTIMIZE__)
constexpr bool kSlowBuild = true;
#else
constexpr bool kSlowBuild = false;
#endif
constexpr int kFrames = kSlowBuild ? 150 : 220;

bool wanted(const std::string& name) {
    if (!kSlowBuild)
        return true;
    return name == "synthetic-doom3-l" || name == "synthetic-grid";
}

struct Suite {
    std::vector<WorkloadTrace> traces;
    std::map<std::string, RunSummary> runs;  // bench|design|mhz|net
    const RunSummary& at(size_t b, Design d, int mhz = 500, const std::string& net = "wifi") {
        return runs.at(traces[b].header.name + "|" + std::string(traitsOf(d).name) + "|" +
                       std::to_string(mhz) + "|" + net);
    }
};

Suite& suite() {
    static Suite* s = [] {
        auto* out = new Suite;
        for (const auto& b : suiteBenches())
            if (wanted(b.name))
                out->traces.push_back(*makeSuiteBench(b.name, kFrames));
        struct Job {
            size_t b;
            Design d;
            int mhz;
            std::string net;
        };
        std::vector<Job> jobs;
        for (size_t b = 0; b < out->traces.size(); ++b) {
            for (Design d : {Design::Local, Design::Static, Design::Ffr, Design::Dfr, Design::Qvr})
                jobs.push_back({b, d, 500, "wifi"});
            for (int mhz : {500, 300})
                for (const char* net : {"wifi", "lte", "5g"})
                    if (!(mhz == 500 && std::string(net) == "wifi"))
                        jobs.push_back({b, Design::Qvr, mhz, net});
        }
        std::vector<RunSummary> results(jobs.size());
        auto work = [&](size_t first) {
            for (size_t i = first; i < jobs.size(); i += 2) {
                const Job& j = jobs[i];
                auto link = makeLink(*networkSpecByName(j.net), 1000 * (j.b + 1) + j.net.size());
                SimConfig cfg;
                cfg.bench = out->traces[j.b].header.name;
                cfg.design = j.d;
                cfg.hardware = defaultHardware(j.mhz);
                cfg.frames = kFrames;
                results[i] = simulate(out->traces[j.b], cfg, **link).summary;
            }
        };
        std::thread t(work, 1);
        work(0);
        t.join();
        for (size_t i = 0; i < jobs.size(); ++i) {
            const Job& j = jobs[i];
            out->runs[out->traces[j.b].header.name + "|" + std::string(traitsOf(j.d).name) + "|" +
                      std::to_string(j.mhz) + "|" + j.net] = results[i];
        }
        return out;
    }();
    return *s;
}

void QvrBeatsDfrAndFfrOnEveryBench() {
    // §6.1: Q-VR > DFR > FFR in end-to-end speedup. UCA only removes work from the GPU, so
    // Q-VR must beat both on every bench.
    Suite& s = suite();
    for (size_t b = 0; b < s.traces.size(); ++b) {
        const double local = s.at(b, Design::Local).mtp_ms_mean;
        const double sq = local / s.at(b, Design::Qvr).mtp_ms_mean;
        EXPECT_GT(sq, local / s.at(b, Design::Dfr).mtp_ms_mean) << s.traces[b].header.name;
        EXPECT_GT(sq, local / s.at(b, Design::Ffr).mtp_ms_mean) << s.traces[b].header.name;
        EXPECT_GT(local / s.at(b, Design::Ffr).mtp_ms_mean, 1.0) << s.traces[b].header.name;
    }
}

void DfrIsAtLeastFfrWhenLiwcReadsGpuTimers() {
    // The paper has DFR 1.1x over FFR. LIWC reads T_local as GPU timers would (first cycle to
    // last, preemptions included, waiting behind a pass not): then DFR sizes the fovea to the
    // balance FFR misses and is not slower than it. Measured from submission instead, the waits
    // behind composition/ATW become "triangle time" and DFR falls behind (docs/MODEL.md §6).
    Suite& s = suite();
    double d = 0, f = 0;
    for (size_t b = 0; b < s.traces.size(); ++b) {
        const double local = s.at(b, Design::Local).mtp_ms_mean;
        d += local / s.at(b, Design::Dfr).mtp_ms_mean;
        f += local / s.at(b, Design::Ffr).mtp_ms_mean;
    }
    EXPECT_GE(d / f, 1.0);
    EXPECT_LT(d / f, 1.2);
}

void SteadyE1IsLargerOnLteAndSmallerOn5gThanOnWifi() {
    Suite& s = suite();
    for (size_t b = 0; b < s.traces.size(); ++b) {
        for (int mhz : {500, 300}) {
            const double w = s.at(b, Design::Qvr, mhz, "wifi").e1_deg_steady;
            EXPECT_GT(s.at(b, Design::Qvr, mhz, "lte").e1_deg_steady, w)
                << s.traces[b].header.name << " @" << mhz;
            EXPECT_LT(s.at(b, Design::Qvr, mhz, "5g").e1_deg_steady, w)
                << s.traces[b].header.name << " @" << mhz;
        }
    }
}

void LowerGpuClockGivesSmallerE1() {
    Suite& s = suite();
    for (size_t b = 0; b < s.traces.size(); ++b)
        for (const char* net : {"wifi", "lte", "5g"})
            EXPECT_LT(s.at(b, Design::Qvr, 300, net).e1_deg_steady,
                      s.at(b, Design::Qvr, 500, net).e1_deg_steady)
                << s.traces[b].header.name << " " << net;
}

void QvrSendsFarFewerBytesThanStatic() {
    Suite& s = suite();
    for (size_t b = 0; b < s.traces.size(); ++b)
        EXPECT_LT(s.at(b, Design::Qvr).bytes_per_frame_mean,
                  0.5 * s.at(b, Design::Static).bytes_per_frame_mean)
            << s.traces[b].header.name;
}

void QvrUsesLessEnergyThanLocal() {
    Suite& s = suite();
    for (size_t b = 0; b < s.traces.size(); ++b)
        EXPECT_LT(s.at(b, Design::Qvr).energy_mj_per_frame,
                  s.at(b, Design::Local).energy_mj_per_frame)
            << s.traces[b].header.name;
}

// One test, so the suite's ~80 runs happen once per process (ctest runs each TEST alone).
TEST(Findings, ThePapersQualitativeFindingsOnTheSyntheticSuite) {
    {
        SCOPED_TRACE("QvrBeatsDfrAndFfrOnEveryBench");
        QvrBeatsDfrAndFfrOnEveryBench();
    }
    {
        SCOPED_TRACE("DfrIsAtLeastFfrWhenLiwcReadsGpuTimers");
        DfrIsAtLeastFfrWhenLiwcReadsGpuTimers();
    }
    {
        SCOPED_TRACE("SteadyE1IsLargerOnLteAndSmallerOn5gThanOnWifi");
        SteadyE1IsLargerOnLteAndSmallerOn5gThanOnWifi();
    }
    {
        SCOPED_TRACE("LowerGpuClockGivesSmallerE1");
        LowerGpuClockGivesSmallerE1();
    }
    {
        SCOPED_TRACE("QvrSendsFarFewerBytesThanStatic");
        QvrSendsFarFewerBytesThanStatic();
    }
    {
        SCOPED_TRACE("QvrUsesLessEnergyThanLocal");
        QvrUsesLessEnergyThanLocal();
    }
}

}  // namespace
}  // namespace qvr
