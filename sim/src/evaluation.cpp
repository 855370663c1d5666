// The experiments of the paper's §6 (Fig. 12–15, Table 4) over the Table 3 suite: the run grid
// of the faithful model and of the variant with one fitted parameter, the headline figures and
// the qualitative findings. The figures and the report are written by eval_report.cpp.
#include "qvr/sim/evaluation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "eval_internal.h"
#include "qvr/core/text_file.h"
#include "qvr/sim/benches.h"

namespace qvr {

namespace fs = std::filesystem;
using namespace eval_detail;

namespace eval_detail {

std::string_view variantSuffix(Variant v) {
    return v == Variant::kFitted ? "-fitted" : "";
}

std::string designKey(Design d, Variant v) {
    std::string s(traitsOf(d).name);
    if (traitsOf(d).split == Split::Foveated)
        s += variantSuffix(v);
    return s;
}

std::string runKey(const std::string& bench, std::string_view name, double mhz,
                   const std::string& net) {
    return fmt::format("{}|{}|{}|{}", bench, name, static_cast<int>(mhz), net);
}

const JobResult& EvalRuns::job(size_t b, std::string_view name, double mhz,
                               const std::string& net) const {
    return by_key.at(runKey(benches.at(b).name, name, mhz, net));
}

double mean(const std::vector<double>& v) {
    if (v.empty())
        return 0.0;
    double s = 0.0;
    for (double x : v)
        s += x;
    return s / static_cast<double>(v.size());
}

std::string fmtNum(double v, int prec) {
    return fmt::format("{:.{}f}", v, prec);
}

// "," and the number, in one string: GCC 12 at -O3 reports a false -Wrestrict for
// "," + std::string temporaries, which -Werror turns into a failed release build.
std::string fmtCell(double v, int prec) {
    return fmt::format(",{:.{}f}", v, prec);
}

}  // namespace eval_detail

namespace {

struct Job {
    size_t bench = 0;
    Design design = Design::Qvr;
    double gpu_mhz = kDefaultMhz;
    std::string net = "wifi";
    bool keep_frames = false;
    std::string name;                      // the run's name in summary.json and the lookups
    const WorkloadTrace* trace = nullptr;  // which trace (codec setting, acuity) it runs on
    bool from_submission = false;          // T_local from submission (sensitivity run)
    bool oracle = false;                   // the oracle picks e1 (Fig. 14's floor)
};

// A per-bench finding holds on at least 6 of 7 benches, a per-cell one on at least 19 of 21
// cells: one bench, or two of 21 cells, may break it when the report shows why.
bool mostBenches(int ok, size_t total) {
    return 7 * static_cast<size_t>(ok) >= 6 * total;
}
bool mostCells(int ok, int total) {
    return 21 * ok >= 19 * total;
}

nlohmann::json runJson(const RunSummary& s) {
    return {{"bench", s.bench},
            {"design", s.design},
            {"gpu_mhz", s.gpu_mhz},
            {"net", s.net},
            {"frames", s.frames},
            {"mtp_ms_mean", s.mtp_ms_mean},
            {"mtp_ms_p99", s.mtp_ms_p99},
            {"fps_mean", s.fps_mean},
            {"fps_pipeline", s.fps_pipeline},
            {"bytes_per_frame_mean", s.bytes_per_frame_mean},
            {"pixels_per_frame_mean", s.pixels_per_frame_mean},
            {"energy_mj_per_frame", s.energy_mj_per_frame},
            {"energy_gpu_mj_per_frame", s.energy_mean.gpuMj()},
            {"energy_radio_mj_per_frame", s.energy_mean.radioMj()},
            {"energy_other_mj_per_frame", s.energy_mean.otherMj()},
            {"energy_mj_breakdown",
             {{"gpu_dynamic", s.energy_mean.gpu_dynamic_mj},
              {"gpu_static", s.energy_mean.gpu_static_mj},
              {"radio", s.energy_mean.radio_mj},
              {"uca", s.energy_mean.uca_mj},
              {"liwc", s.energy_mean.liwc_mj}}},
            {"radio_w_max", s.radio_w_max},
            {"display_dram_mb_per_frame", s.display_dram_mb_per_frame},
            {"display_dram_ms_mean", s.display_dram_ms_mean},
            {"e1_deg_mean", s.e1_deg_mean},
            {"e1_deg_steady", s.e1_deg_steady},
            {"latency_ratio_final", s.latency_ratio_final},
            {"t_local_ms_mean", s.t_local_ms_mean},
            {"t_remote_ms_mean", s.t_remote_ms_mean},
            {"render_wait_ms_mean", s.render_wait_ms_mean},
            {"gpu_ms_mean", s.gpu_ms_mean},
            {"net_ms_mean", s.net_ms_mean},
            {"comp_ms_mean", s.comp_ms_mean},
            {"atw_ms_mean", s.atw_ms_mean},
            {"uca_ms_mean", s.uca_ms_mean},
            {"preemptions_per_frame", s.preemptions_per_frame},
            {"meets_refresh", s.meets_refresh}};
}

}  // namespace

bool Headline::fittedFar() const {
    return paper != 0.0 && std::fabs(fitted / paper - 1.0) > 0.25;
}

uint64_t benchLinkSeed(const std::string& bench, const std::string& net) {
    // FNV-1a over "bench|net": stable across platforms and standard libraries.
    uint64_t h = 14695981039346656037ULL;
    for (const char c : bench + "|" + net) {
        h ^= static_cast<unsigned char>(c);
        h *= 1099511628211ULL;
    }
    return h;
}

double fitAcuitySlope(const std::function<double(double)>& reduction_at, double target, double lo,
                      double hi, double tolerance) {
    // Regula falsi (Illinois) in log m, keeping the slope closest to the target.
    double a = std::log(lo), b = std::log(hi);
    double fa = reduction_at(lo) - target, fb = reduction_at(hi) - target;
    double best = std::fabs(fa) < std::fabs(fb) ? lo : hi;
    double best_err = std::min(std::fabs(fa), std::fabs(fb));
    if (fa * fb > 0.0)
        return best;  // the target is outside the bracket: the nearer end
    int side = 0;
    for (int i = 0; i < 16 && best_err > tolerance; ++i) {
        const double c = (a * fb - b * fa) / (fb - fa);
        const double fc = reduction_at(std::exp(c)) - target;
        if (std::fabs(fc) < best_err) {
            best_err = std::fabs(fc);
            best = std::exp(c);
        }
        if (fc * fb > 0.0) {
            b = c;
            fb = fc;
            if (side == -1)
                fa /= 2.0;
            side = -1;
        } else {
            a = c;
            fa = fc;
            if (side == 1)
                fb /= 2.0;
            side = 1;
        }
    }
    return best;
}

Status writeSummaryJson(const std::string& path, const std::vector<RunSummary>& runs) {
    nlohmann::json j;
    j["runs"] = nlohmann::json::array();
    for (const auto& r : runs)
        j["runs"].push_back(runJson(r));
    j["notes"] = {
        {"mtp_ms", "2 ms sensor + control logic to end of composition/ATW + 5 ms display"},
        {"fps", "1000 / mean over frames of max(T_GPU, T_network) (paper: min(1/T_GPU, 1/T_net))"},
        {"fps_pipeline", "frames shown per second in the event timeline (the displayed rate)"},
        {"bytes", "downlink payload per frame"},
        {"pixels", "shaded pixels per frame, both eyes, each layer at its own resolution"},
        {"energy",
         "per frame: GPU (dynamic + leakage), radio (power while receiving x "
         "transfer time), other (UCA + LIWC); docs/EVAL.md"},
        {"designs",
         "'-fitted': the acuity slope fitted to the paper's 41% shaded-pixel "
         "reduction; '-oracle': e1 picked by the oracle policy"},
        {"latency_ratio_final", "median T_remote/T_local over the last 30 frames"},
        {"e1_deg_steady", "mean e1 after the warm-up (Table 4)"}};
    return writeJsonFile(path, j);
}

Status writeFramesCsv(const std::string& path, const std::vector<FrameRecord>& frames) {
    std::string s =
        "frame,e1_deg,e2_deg,start_ms,render_start_ms,render_end_ms,remote_ready_ms,"
        "display_ready_ms,render_work_ms,t_local_ms,t_remote_ms,net_ms,server_render_ms,"
        "encode_ms,decode_ms,comp_ms,atw_ms,uca_ms,gpu_ms,preemptions,bytes,goodput_bps,"
        "shaded_pixels,mtp_ms,fps,latency_ratio,energy_gpu_dynamic_mj,energy_gpu_static_mj,"
        "energy_radio_mj,energy_uca_mj,energy_liwc_mj,energy_total_mj\n";
    for (const FrameRecord& r : frames) {
        s += fmt::format(
            "{},{:.3f},{:.3f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},"
            "{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{:.0f},{:.0f},{:.0f},{:.4f},"
            "{:.3f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f}\n",
            r.index, r.e1_deg, r.e2_deg, r.pose_ms, r.render_start_ms, r.render_end_ms,
            r.remote_ready_ms, r.display_ready_ms, r.render_work_ms, r.t_local_ms, r.t_remote_ms,
            r.net_ms, r.server_render_ms, r.encode_ms, r.decode_ms, r.comp_ms, r.atw_ms, r.uca_ms,
            r.gpu_ms, r.preemptions, r.bytes, r.goodput_bps, r.shaded_pixels, r.mtp_ms, r.fps,
            r.latency_ratio, r.energy.gpu_dynamic_mj, r.energy.gpu_static_mj, r.energy.radio_mj,
            r.energy.uca_mj, r.energy.liwc_mj, r.energy.total());
    }
    return writeTextFile(path, s);
}

namespace {

// What every job of one evaluation shares.
struct RunContext {
    const EvalOptions& options;
    const EvalRuns& runs;
    std::map<double, HardwareConfig> hardware;  // by GPU clock
    int long_frames = 0;                        // runs whose frames are kept (Fig. 14)
};

Status checkOptions(const EvalOptions& options) {
    if (options.frames < 30 || options.frames > 100'000)
        return makeError(fmt::format("--frames must be in 30..100000, got {}", options.frames));
    if (options.jobs < 1 || options.jobs > 256)
        return makeError(fmt::format("--jobs must be in 1..256, got {}", options.jobs));
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec)
        return makeError(fmt::format("cannot create '{}': {}", options.out_dir, ec.message()));
    return Status::success();
}

bool namesBench(const std::string& n, const BenchInfo& b) {
    return n == b.name || "synthetic-" + n == b.name;
}

// The selected benches, their traces in both codec settings when recorded, and the Mahimahi
// traces (checked before anything runs).
Status loadSuite(const EvalOptions& options, EvalRuns& runs) {
    for (const auto& path : options.mahimahi_traces) {
        auto t = loadMahimahiTrace(path);
        if (!t)
            return makeError(t.error());
        runs.trace_nets.push_back("trace:" + path);
    }
    for (const BenchInfo& b : suiteBenches()) {
        if (options.benches.empty() || std::any_of(options.benches.begin(), options.benches.end(),
                                                   [&](const auto& n) { return namesBench(n, b); }))
            runs.benches.push_back(b);
    }
    for (const auto& n : options.benches) {
        if (std::none_of(runs.benches.begin(), runs.benches.end(),
                         [&](const BenchInfo& b) { return namesBench(n, b); }))
            return makeError(
                fmt::format("unknown bench '{}': expected one of {}", n, suiteBenchNamesList()));
    }
    const int frames = std::max(options.frames, kFig14Frames);
    runs.codec = options.codec_model;
    runs.other_codec =
        runs.codec == CodecModel::kLossless ? CodecModel::kStream : CodecModel::kLossless;
    bool have_other = selectedSuite() == SuiteKind::kRecorded;
    for (const BenchInfo& b : runs.benches) {
        auto t = makeSuiteBench(b.name, frames, runs.codec);
        if (!t)
            return makeError(t.error());
        runs.traces.push_back(std::move(*t));
        if (have_other) {
            auto o = makeSuiteBench(b.name, frames, runs.other_codec);
            have_other = o.ok();
            if (o)
                runs.other_traces.push_back(std::move(*o));
        }
    }
    if (!have_other)
        runs.other_traces.clear();
    return Status::success();
}

// The faithful grid: every design at the default point (Fig. 12–14); Q-VR at every frequency ×
// network (Table 4, Fig. 15); the local baseline at every frequency (Fig. 15's reference); DFR
// with T_local from submission; every design with the other codec setting; the oracle on
// Q-VR's link (Fig. 14's floor); ffr, dfr and qvr on each Mahimahi trace.
std::vector<Job> faithfulJobs(const EvalRuns& runs) {
    std::vector<Job> jobs;
    for (size_t b = 0; b < runs.size(); ++b) {
        const WorkloadTrace* t = &runs.traces[b];
        for (Design d : allDesigns())
            jobs.push_back({b, d, kDefaultMhz, "wifi", d == Design::Qvr, designKey(d), t});
        jobs.push_back({b, Design::Dfr, kDefaultMhz, "wifi", false, "dfr-submission", t, true});
        jobs.push_back({b, Design::Qvr, kDefaultMhz, "wifi", true, "qvr-oracle", t, false, true});
        if (!runs.other_traces.empty())
            for (Design d : allDesigns())
                jobs.push_back({b, d, kDefaultMhz, "wifi", false,
                                designKey(d) + "@" + codecModelName(runs.other_codec),
                                &runs.other_traces[b]});
        for (double mhz : kFreqsMhz) {
            for (const auto& net : kNets)
                if (mhz != kDefaultMhz || net != "wifi")
                    jobs.push_back({b, Design::Qvr, mhz, net, false, "qvr", t});
            if (mhz != kDefaultMhz)
                jobs.push_back({b, Design::Local, mhz, "wifi", false, "local", t});
        }
    }
    for (const auto& net : runs.trace_nets)
        for (size_t b = 0; b < runs.size(); ++b)
            for (Design d : {Design::Ffr, Design::Dfr, Design::Qvr})
                jobs.push_back({b, d, kDefaultMhz, net, false, designKey(d), &runs.traces[b]});
    return jobs;
}

// The fitted variant's grid on `fitted` traces: the foveated designs at the default point and
// Q-VR at every frequency × network. The other designs do not depend on the acuity model.
std::vector<Job> fittedJobs(const EvalRuns& runs, const std::vector<WorkloadTrace>& fitted) {
    std::vector<Job> jobs;
    for (size_t b = 0; b < runs.size(); ++b) {
        for (Design d : {Design::Ffr, Design::Dfr, Design::Sw, Design::Qvr})
            jobs.push_back(
                {b, d, kDefaultMhz, "wifi", false, designKey(d, Variant::kFitted), &fitted[b]});
        for (double mhz : kFreqsMhz)
            for (const auto& net : kNets)
                if (mhz != kDefaultMhz || net != "wifi")
                    jobs.push_back({b, Design::Qvr, mhz, net, false, "qvr-fitted", &fitted[b]});
    }
    return jobs;
}

Expected<std::map<double, HardwareConfig>> hardwareByClock(const EvalOptions& options) {
    std::map<double, HardwareConfig> hardware;
    for (double mhz : kFreqsMhz) {
        if (options.hardware_path.empty()) {
            hardware[mhz] = defaultHardware(mhz);
            continue;
        }
        auto hw = loadHardwareConfig(options.hardware_path, mhz);
        if (!hw)
            return makeError(hw.error());
        hardware[mhz] = *hw;
    }
    return hardware;
}

Expected<JobResult> runJob(const Job& job, const RunContext& ctx) {
    auto spec = networkSpecByName(job.net);
    if (!spec)
        return makeError("cannot build network " + job.net);
    const std::string& bench = ctx.runs.benches[job.bench].name;
    auto link = makeLink(*spec, benchLinkSeed(bench, job.net));
    if (!link)
        return makeError("cannot build network " + job.net);
    SimConfig cfg;
    cfg.bench = bench;
    cfg.design = job.design;
    cfg.hardware = ctx.hardware.at(job.gpu_mhz);
    cfg.t_local_from_submission = job.from_submission;
    cfg.oracle_policy = job.oracle;
    cfg.vsync_paced = ctx.options.vsync_paced;
    cfg.frames = job.keep_frames ? ctx.long_frames : ctx.options.frames;
    // The oracle scans ~160 layer plans a frame: it runs the frames Fig. 14's check reads of it.
    if (job.oracle)
        cfg.frames = kOracleFrames;
    RunResult run = simulate(*job.trace, cfg, **link);
    JobResult r;
    r.summary = std::move(run.summary);
    r.summary.design = job.name;
    if (job.keep_frames)
        r.frames = std::move(run.frames);
    return r;
}

// Runs jobs on options.jobs threads; `on_done` is called after each, serialised.
Expected<std::vector<JobResult>> runJobs(const std::vector<Job>& jobs, const RunContext& ctx,
                                         const std::function<void()>& on_done) {
    std::vector<JobResult> results(jobs.size());
    std::atomic<size_t> next{0};
    std::mutex mutex;
    std::string first_error;
    auto worker = [&]() {
        for (size_t i = next.fetch_add(1); i < jobs.size(); i = next.fetch_add(1)) {
            auto r = runJob(jobs[i], ctx);
            std::lock_guard<std::mutex> lock(mutex);
            if (!r) {
                if (first_error.empty())
                    first_error = r.error();
                continue;
            }
            results[i] = std::move(*r);
            if (on_done)
                on_done();
        }
    };
    std::vector<std::thread> pool;
    const int n_threads = std::min<int>(ctx.options.jobs, static_cast<int>(jobs.size()));
    for (int t = 0; t < n_threads; ++t)
        pool.emplace_back(worker);
    for (auto& t : pool)
        t.join();
    if (!first_error.empty())
        return makeError(first_error);
    return results;
}

std::vector<WorkloadTrace> withSlope(const std::vector<WorkloadTrace>& traces, double slope) {
    std::vector<WorkloadTrace> out = traces;
    for (WorkloadTrace& t : out)
        t.header.profile.acuity.slope = slope;
    return out;
}

// The one fitted parameter: the acuity slope m at which Q-VR's mean shaded-pixel reduction over
// the whole suite at the default point is the paper's 41%, searched between 1e-4 (no reduction)
// and Guenter's slope. Fitted once, over the whole suite whatever the selection, so that a bench's
// fitted numbers are the same alone or in the suite.
Expected<double> fitSlope(const RunContext& ctx) {
    EvalRuns suite;
    const bool whole = ctx.runs.size() == suiteBenches().size();
    suite.benches = whole ? ctx.runs.benches : suiteBenches();
    if (whole) {
        suite.traces = ctx.runs.traces;
    } else {
        for (const BenchInfo& b : suite.benches) {
            auto t = makeSuiteBench(b.name, ctx.long_frames, ctx.runs.codec);
            if (!t)
                return makeError(t.error());
            suite.traces.push_back(std::move(*t));
        }
    }
    const RunContext fit_ctx{ctx.options, suite, ctx.hardware, ctx.long_frames};
    const double guenter = suite.traces.front().header.profile.acuity.slope;
    std::string error;
    auto reduction_at = [&](double slope) {
        const std::vector<WorkloadTrace> traces = withSlope(suite.traces, slope);
        std::vector<Job> jobs;
        for (size_t b = 0; b < suite.size(); ++b)
            jobs.push_back({b, Design::Qvr, kDefaultMhz, "wifi", false, "qvr-fit", &traces[b]});
        auto results = runJobs(jobs, fit_ctx, {});
        if (!results) {
            error = results.error();
            return 0.0;
        }
        std::vector<double> kept;
        for (size_t b = 0; b < jobs.size(); ++b) {
            const HmdProfile& p = traces[b].header.profile;
            kept.push_back((*results)[b].summary.pixels_per_frame_mean /
                           (2.0 * p.width_px * static_cast<double>(p.height_px)));
        }
        return 1.0 - mean(kept);
    };
    const double slope = fitAcuitySlope(reduction_at, kPaperPixelReduction, 1e-4, guenter, 0.005);
    if (!error.empty())
        return makeError(error);
    return slope;
}

void addResults(const std::vector<Job>& jobs, std::vector<JobResult>&& results, EvalRuns& runs,
                EvalOutput& output) {
    for (size_t i = 0; i < jobs.size(); ++i) {
        output.runs.push_back(results[i].summary);
        runs.by_key[runKey(runs.benches[jobs[i].bench].name, jobs[i].name, jobs[i].gpu_mhz,
                           jobs[i].net)] = std::move(results[i]);
    }
}

// Per bench: a design's figure `f(design run, local run)`.
std::vector<double> perBench(const EvalRuns& runs, Design d, Variant v,
                             const std::function<double(const RunSummary&, size_t)>& f) {
    std::vector<double> out;
    for (size_t b = 0; b < runs.size(); ++b)
        out.push_back(f(runs.at(b, d, v), b));
    return out;
}

double meanOf(const EvalRuns& runs, Design d, Variant v, double RunSummary::*field) {
    return mean(perBench(runs, d, v, [&](const RunSummary& s, size_t) { return s.*field; }));
}

std::vector<double> speedups(const EvalRuns& runs, Design d, Variant v) {
    return perBench(runs, d, v, [&](const RunSummary& s, size_t b) {
        return runs.at(b, Design::Local).mtp_ms_mean / s.mtp_ms_mean;
    });
}

double ratioOver(const EvalRuns& runs, Design d, Design base, Variant v,
                 double RunSummary::*field) {
    return mean(perBench(runs, d, v, [&](const RunSummary& s, size_t b) {
        return s.*field / runs.at(b, base, v).*field;
    }));
}

double pixelShare(const EvalRuns& runs, Variant v) {
    return mean(perBench(runs, Design::Qvr, v, [&](const RunSummary& s, size_t b) {
        return s.pixels_per_frame_mean / runs.at(b, Design::Remote).pixels_per_frame_mean;
    }));
}

double energyShare(const EvalRuns& runs, Variant v) {
    std::vector<double> all;
    for (double mhz : kFreqsMhz)
        for (const auto& net : kNets)
            for (size_t b = 0; b < runs.size(); ++b)
                all.push_back(
                    runs.at(b, Design::Qvr, v, mhz, net).energy_mj_per_frame /
                    runs.at(b, Design::Local, Variant::kFaithful, mhz).energy_mj_per_frame);
    return mean(all);
}

// A design's per-frame quantities, suite means at the default point.
std::string quantities(const EvalRuns& runs, Design d, Variant v) {
    auto m = [&](double RunSummary::*f) { return meanOf(runs, d, v, f); };
    std::string s = fmt::format(
        "{}: MTP {:.1f} ms, T_GPU {:.2f} ms, T_network {:.2f} ms, T_local {:.2f} ms, T_remote "
        "{:.2f} ms",
        traitsOf(d).name, m(&RunSummary::mtp_ms_mean), m(&RunSummary::gpu_ms_mean),
        m(&RunSummary::net_ms_mean), m(&RunSummary::t_local_ms_mean),
        m(&RunSummary::t_remote_ms_mean));
    if (traitsOf(d).split == Split::Foveated)
        s += fmt::format(", e1 {:.1f} deg", m(&RunSummary::e1_deg_steady));
    if (m(&RunSummary::comp_ms_mean) + m(&RunSummary::atw_ms_mean) > 0.0)
        s += fmt::format(", C+ATW on the GPU {:.2f} ms",
                         m(&RunSummary::comp_ms_mean) + m(&RunSummary::atw_ms_mean));
    if (m(&RunSummary::uca_ms_mean) > 0.0)
        s += fmt::format(", UCA {:.2f} ms (not in T_GPU)", m(&RunSummary::uca_ms_mean));
    s += fmt::format(", {:.1f} KB/frame, shown {:.0f} FPS",
                     m(&RunSummary::bytes_per_frame_mean) / 1e3, m(&RunSummary::fps_pipeline));
    return s;
}

std::string energyQuantities(const EvalRuns& runs, Design d, Variant v) {
    double gpu = 0.0, radio = 0.0, other = 0.0;
    for (size_t b = 0; b < runs.size(); ++b) {
        const FrameEnergy& e = runs.at(b, d, v).energy_mean;
        gpu += e.gpuMj() / static_cast<double>(runs.size());
        radio += e.radioMj() / static_cast<double>(runs.size());
        other += e.otherMj() / static_cast<double>(runs.size());
    }
    return fmt::format("{} at 500 MHz on Wi-Fi: GPU {:.2f} + radio {:.2f} + other {:.3f} mJ/frame",
                       traitsOf(d).name, gpu, radio, other);
}

std::vector<Headline> computeHeadlines(const EvalRuns& runs) {
    std::vector<Headline> h;
    const Variant kF = Variant::kFaithful, kV = Variant::kFitted;
    auto both = [&](const std::string& metric, double paper, const std::string& unit,
                    const std::function<double(Variant)>& f, std::string mechanism) {
        h.push_back({metric, paper, f(kF), f(kV), unit, std::move(mechanism)});
    };
    auto q = [&](Design d) { return quantities(runs, d, kV); };
    both(
        "Q-VR end-to-end speedup over local (mean)", 3.4, "x",
        [&](Variant v) { return mean(speedups(runs, Design::Qvr, v)); },
        q(Design::Local) + "; " + q(Design::Qvr));
    // Q-VR's FPS over a baseline, by the formula FPS and by the displayed rate.
    struct Baseline {
        const char* name;
        Design design;
        double paper;
    };
    struct Rate {
        const char* name;
        double RunSummary::*fps;
    };
    for (const Baseline& base :
         {Baseline{"static", Design::Static, 4.1}, Baseline{"software Q-VR", Design::Sw, 2.8}}) {
        for (const Rate& rate : {Rate{"formula FPS", &RunSummary::fps_mean},
                                 Rate{"displayed rate", &RunSummary::fps_pipeline}}) {
            both(
                fmt::format("Q-VR FPS over {} ({})", base.name, rate.name), base.paper, "x",
                [&](Variant v) { return ratioOver(runs, Design::Qvr, base.design, v, rate.fps); },
                q(base.design) + "; " + q(Design::Qvr));
        }
    }
    both(
        "Q-VR data reduction vs static", 85.0, "%",
        [&](Variant v) {
            return 100.0 * (1.0 - ratioOver(runs, Design::Qvr, Design::Static, v,
                                            &RunSummary::bytes_per_frame_mean));
        },
        q(Design::Static) + "; " + q(Design::Qvr));
    both(
        "Q-VR shaded-pixel reduction vs full frame (fitted to)", 41.0, "%",
        [&](Variant v) { return 100.0 * (1.0 - pixelShare(runs, v)); },
        fmt::format("the fitted slope is chosen so that this is 41%; Q-VR shades {:.1f}% of the "
                    "frame at e1 {:.1f} deg",
                    100.0 * pixelShare(runs, kV),
                    meanOf(runs, Design::Qvr, kV, &RunSummary::e1_deg_steady)));
    both(
        "Q-VR energy reduction vs local (all freq x net)", 73.0, "%",
        [&](Variant v) { return 100.0 * (1.0 - energyShare(runs, v)); },
        energyQuantities(runs, Design::Local, kF) + "; " + energyQuantities(runs, Design::Qvr, kV));
    both(
        "FFR end-to-end speedup over local (mean)", 1.75, "x",
        [&](Variant v) { return mean(speedups(runs, Design::Ffr, v)); },
        q(Design::Local) + "; " + q(Design::Ffr));
    both(
        "DFR speedup over FFR (mean)", 1.1, "x",
        [&](Variant v) {
            return mean(speedups(runs, Design::Dfr, v)) / mean(speedups(runs, Design::Ffr, v));
        },
        q(Design::Ffr) + "; " + q(Design::Dfr));
    return h;
}

Finding qvrBeatsDfrAndFfr(const EvalRuns& runs) {
    const auto q = speedups(runs, Design::Qvr, Variant::kFaithful);
    const auto d = speedups(runs, Design::Dfr, Variant::kFaithful);
    const auto f = speedups(runs, Design::Ffr, Variant::kFaithful);
    int ok = 0;
    std::string bad;
    for (size_t b = 0; b < runs.size(); ++b) {
        if (q[b] >= d[b] && q[b] >= f[b])
            ++ok;
        else
            bad += fmt::format(" {} (qvr {:.2f}, dfr {:.2f}, ffr {:.2f});", runs.benches[b].label,
                               q[b], d[b], f[b]);
    }
    return {
        "qvr >= dfr and qvr >= ffr in end-to-end speedup", mostBenches(ok, runs.size()),
        fmt::format("holds for {}/{} benches; means qvr {:.2f}x, dfr {:.2f}x, ffr {:.2f}x.{}", ok,
                    runs.size(), mean(q), mean(d), mean(f), bad.empty() ? "" : " Fails:" + bad)};
}

Finding dfrBeatsFfr(const EvalRuns& runs) {
    const auto d = speedups(runs, Design::Dfr, Variant::kFaithful);
    const auto f = speedups(runs, Design::Ffr, Variant::kFaithful);
    int ok = 0;
    std::string detail;
    for (size_t b = 0; b < runs.size(); ++b) {
        ok += d[b] >= f[b] ? 1 : 0;
        detail += fmt::format(" {} {:.2f}/{:.2f};", runs.benches[b].label, d[b], f[b]);
    }
    return {"dfr >= ffr in end-to-end speedup", mostBenches(ok, runs.size()),
            fmt::format("holds for {}/{} benches (dfr/ffr speedup:{}) mean ratio {:.3f}; see "
                        "'Where we differ' below",
                        ok, runs.size(), detail, mean(d) / mean(f))};
}

// Steady e1 ordered across three runs per cell: `order(a, b, c)` names what must hold.
Finding e1Order(const EvalRuns& runs, bool by_network) {
    int ok = 0, total = 0;
    std::string bad;
    for (size_t b = 0; b < runs.size(); ++b) {
        const std::vector<std::string> cells =
            by_network ? std::vector<std::string>{"500", "400", "300"} : kNets;
        for (const auto& cell : cells) {
            auto e1 = [&](double mhz, const std::string& net) {
                return runs.at(b, Design::Qvr, Variant::kFaithful, mhz, net).e1_deg_steady;
            };
            double x, y, z;
            if (by_network) {
                const double mhz = std::stod(cell);
                x = e1(mhz, "lte"), y = e1(mhz, "wifi"), z = e1(mhz, "5g");
            } else {
                x = e1(500, cell), y = e1(400, cell), z = e1(300, cell);
            }
            ++total;
            if (x >= y && y >= z)
                ++ok;
            else
                bad += fmt::format(" {}@{} ({:.1f}, {:.1f}, {:.1f});", runs.benches[b].label, cell,
                                   x, y, z);
        }
    }
    if (by_network)
        return {"steady e1: LTE >= Wi-Fi >= 5G", mostCells(ok, total),
                fmt::format("holds for {}/{} bench x frequency cells.{}", ok, total,
                            bad.empty() ? "" : " Fails (lte, wifi, 5g):" + bad)};
    return {"lower GPU frequency gives a smaller e1", mostCells(ok, total),
            fmt::format("holds for {}/{} bench x network cells.{}", ok, total,
                        bad.empty() ? "" : " Fails (500, 400, 300 MHz):" + bad)};
}

Finding fewerBytesThanStatic(const EvalRuns& runs) {
    const auto r =
        perBench(runs, Design::Qvr, Variant::kFaithful, [&](const RunSummary& s, size_t b) {
            return s.bytes_per_frame_mean / runs.at(b, Design::Static).bytes_per_frame_mean;
        });
    return {"qvr sends far fewer bytes than static (< 50%)", mean(r) < 0.5,
            fmt::format("qvr/static bytes = {:.3f} on average (max {:.3f})", mean(r),
                        *std::max_element(r.begin(), r.end()))};
}

// The figures' CSV and plots in order, up to the first that cannot be written; the CSV text the
// report quotes is kept in `report`.
Status writeFigures(const EvalRuns& runs, Outputs& out, ReportInputs& report) {
    const auto keep = [](Expected<std::string> csv, std::string& into) -> Status {
        if (!csv)
            return makeError(csv.error());
        into = std::move(*csv);
        return Status::success();
    };
    Status st = keep(writeFig12(runs, out), report.fig12);
    if (st)
        st = keep(writeFig13(runs, out), report.fig13);
    if (st)
        st = writeFig14(runs, out);
    if (st)
        st = keep(writeTable4(runs, out), report.t4);
    if (st)
        st = keep(writeFig15(runs, out), report.f15);
    if (st)
        st = writeMahimahi(runs, out);
    return st;
}

}  // namespace

Expected<EvalOutput> runEvaluation(const EvalOptions& options) {
    if (Status st = checkOptions(options); !st)
        return makeError(st.error());
    EvalRuns runs;
    if (Status st = loadSuite(options, runs); !st)
        return makeError(st.error());
    auto hardware = hardwareByClock(options);
    if (!hardware)
        return makeError(hardware.error());
    RunContext ctx{options, runs, std::move(*hardware), std::max(options.frames, kFig14Frames)};

    // The one fitted parameter first; then both grids, with progress over both.
    auto slope = fitSlope(ctx);
    if (!slope)
        return makeError(slope.error());
    runs.fitted_slope = *slope;
    const std::vector<WorkloadTrace> fitted = withSlope(runs.traces, *slope);
    const std::vector<Job> faithful = faithfulJobs(runs);
    const std::vector<Job> fitted_jobs = fittedJobs(runs, fitted);
    const int total = static_cast<int>(faithful.size() + fitted_jobs.size());
    int done = 0;
    auto progress = [&]() {
        if (options.progress)
            options.progress(++done, total);
    };
    EvalOutput output;
    output.fitted_slope = *slope;
    for (const std::vector<Job>* jobs : {&faithful, &fitted_jobs}) {
        auto results = runJobs(*jobs, ctx, progress);
        if (!results)
            return makeError(results.error());
        addResults(*jobs, std::move(*results), runs, output);
    }

    Outputs out(options.out_dir);
    ReportInputs report{options, runs, output, "", "", "", ""};
    if (Status st = writeFigures(runs, out, report); !st)
        return makeError(st.error());

    output.headlines = computeHeadlines(runs);
    output.findings = {qvrBeatsDfrAndFfr(runs), dfrBeatsFfr(runs), e1Order(runs, true),
                       e1Order(runs, false), fewerBytesThanStatic(runs)};
    auto fig14 = fig14Finding(runs, out);
    if (!fig14)
        return makeError(fig14.error());
    output.findings.push_back(std::move(*fig14));

    if (Status st = writeSummaryJson((out.dir() / "summary.json").string(), output.runs); !st)
        return makeError(st.error());
    out.files().push_back("summary.json");
    output.plot_note = out.plotNote();
    if (Status st = writeReport(report, out); !st)
        return makeError(st.error());
    output.files = out.files();
    return output;
}

}  // namespace qvr
