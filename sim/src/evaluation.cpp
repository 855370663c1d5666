// The experiments of the paper's §6 (Fig. 12–15, Table 4) over the Table 3 suite: run grid,
// CSV, gnuplot figures, report.html and summary.json.
#include "qvr/sim/evaluation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/report/html_report.h"
#include "qvr/sim/benches.h"

namespace qvr {

namespace fs = std::filesystem;

namespace {

constexpr double kDefaultMhz = 500.0;
const std::vector<double> kFreqsMhz = {500.0, 400.0, 300.0};
const std::vector<std::string> kNets = {"wifi", "lte", "5g"};
constexpr int kFig14Frames = 300;

struct Job {
    size_t bench = 0;
    Design design = Design::Qvr;
    double gpu_mhz = kDefaultMhz;
    std::string net = "wifi";
    bool keep_frames = false;
    bool from_submission = false;  // T_local from submission (sensitivity run)
    bool other_codec = false;      // the codec setting that is not the default (both shown)
};

// A run's design name with its variant: "dfr-submission", "qvr@stream".
std::string variantName(std::string_view design, bool from_submission, bool other_codec,
                        CodecModel other) {
    std::string s(design);
    if (from_submission)
        s += "-submission";
    if (other_codec)
        s += std::string("@") + codecModelName(other);
    return s;
}

struct JobResult {
    RunSummary summary;
    std::vector<FrameRecord> frames;  // only when kept
};

// A per-bench finding holds on at least 6 of 7 benches, a per-cell one on at least 19 of 21
// cells (issue 13's bar: one bench, or two of 21 cells, may break it when the report shows why).
bool mostBenches(int ok, size_t total) {
    return 7 * static_cast<size_t>(ok) >= 6 * total;
}
bool mostCells(int ok, int total) {
    return 21 * ok >= 19 * total;
}

std::string key(const std::string& bench, std::string_view design, double mhz,
                const std::string& net) {
    return fmt::format("{}|{}|{}|{}", bench, design, static_cast<int>(mhz), net);
}

double mean(const std::vector<double>& v) {
    if (v.empty())
        return 0.0;
    double s = 0.0;
    for (double x : v)
        s += x;
    return s / static_cast<double>(v.size());
}

Status writeText(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    if (!out)
        return makeError(fmt::format("cannot write '{}'", path.string()));
    out << text;
    if (!out)
        return makeError(fmt::format("error writing '{}'", path.string()));
    return Status::success();
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
            {"energy_mj_breakdown",
             {{"gpu_dynamic", s.energy_mean.gpu_dynamic_mj},
              {"gpu_static", s.energy_mean.gpu_static_mj},
              {"radio", s.energy_mean.radio_mj},
              {"uca", s.energy_mean.uca_mj},
              {"liwc", s.energy_mean.liwc_mj}}},
            {"e1_deg_mean", s.e1_deg_mean},
            {"e1_deg_steady", s.e1_deg_steady},
            {"latency_ratio_final", s.latency_ratio_final},
            {"t_local_ms_mean", s.t_local_ms_mean},
            {"t_remote_ms_mean", s.t_remote_ms_mean},
            {"render_wait_ms_mean", s.render_wait_ms_mean},
            {"gpu_ms_mean", s.gpu_ms_mean},
            {"net_ms_mean", s.net_ms_mean},
            {"preemptions_per_frame", s.preemptions_per_frame},
            {"meets_refresh", s.meets_refresh}};
}

std::string fmtNum(double v, int prec = 2) {
    return fmt::format("{:.{}f}", v, prec);
}

// "," and the number, in one string: GCC 12 at -O3 reports a false -Wrestrict for
// "," + std::string temporaries, which -Werror turns into a failed release build.
std::string fmtCell(double v, int prec = 2) {
    return fmt::format(",{:.{}f}", v, prec);
}

}  // namespace

Status writeSummaryJson(const std::string& path, const std::vector<RunSummary>& runs) {
    nlohmann::json j;
    j["runs"] = nlohmann::json::array();
    for (const auto& r : runs)
        j["runs"].push_back(runJson(r));
    j["notes"] = {
        {"mtp_ms", "2 ms sensor + control logic to end of composition/ATW + 5 ms display"},
        {"fps", "1000 / mean over frames of max(T_GPU, T_network) (paper: min(1/T_GPU, 1/T_net))"},
        {"bytes", "downlink payload per frame"},
        {"pixels", "shaded pixels per frame, both eyes, each layer at its own resolution"},
        {"latency_ratio_final", "median T_remote/T_local over the last 30 frames"},
        {"e1_deg_steady", "mean e1 after the warm-up (Table 4)"}};
    return writeText(path, j.dump(2) + "\n");
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
            r.index, r.e1_deg, r.e2_deg, r.start_ms, r.render_start_ms, r.render_end_ms,
            r.remote_ready_ms, r.display_ready_ms, r.render_work_ms, r.t_local_ms, r.t_remote_ms,
            r.net_ms, r.server_render_ms, r.encode_ms, r.decode_ms, r.comp_ms, r.atw_ms, r.uca_ms,
            r.gpu_ms, r.preemptions, r.bytes, r.goodput_bps, r.shaded_pixels, r.mtp_ms, r.fps,
            r.latency_ratio, r.energy.gpu_dynamic_mj, r.energy.gpu_static_mj, r.energy.radio_mj,
            r.energy.uca_mj, r.energy.liwc_mj, r.energy.total());
    }
    return writeText(path, s);
}

Expected<EvalOutput> runEvaluation(const EvalOptions& options) {
    if (options.frames < 30 || options.frames > 100'000)
        return makeError(fmt::format("--frames must be in 30..100000, got {}", options.frames));
    if (options.jobs < 1 || options.jobs > 256)
        return makeError(fmt::format("--jobs must be in 1..256, got {}", options.jobs));
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec)
        return makeError(fmt::format("cannot create '{}': {}", options.out_dir, ec.message()));
    const fs::path out(options.out_dir);

    // Trace-driven links: the designs whose behaviour depends on the link's variation. The
    // traces are checked before anything runs.
    const std::vector<Design> trace_designs = {Design::Ffr, Design::Dfr, Design::Qvr};
    std::vector<std::string> trace_nets;
    for (const auto& path : options.mahimahi_traces) {
        auto t = loadMahimahiTrace(path);
        if (!t)
            return makeError(t.error());
        trace_nets.push_back("trace:" + path);
    }

    std::vector<BenchInfo> benches;
    for (const BenchInfo& b : suiteBenches()) {
        const bool wanted =
            options.benches.empty() ||
            std::any_of(options.benches.begin(), options.benches.end(),
                        [&](const auto& n) { return n == b.name || "synthetic-" + n == b.name; });
        if (wanted)
            benches.push_back(b);
    }
    for (const auto& n : options.benches) {
        const bool known = std::any_of(benches.begin(), benches.end(), [&](const BenchInfo& b) {
            return n == b.name || "synthetic-" + n == b.name;
        });
        if (!known)
            return makeError(
                fmt::format("unknown bench '{}': expected one of {}", n, suiteBenchNamesList()));
    }
    const int frames = std::max(options.frames, kFig14Frames);
    const CodecModel other_codec =
        options.codec_model == CodecModel::kLossless ? CodecModel::kStream : CodecModel::kLossless;
    const bool recorded = selectedSuite() == SuiteKind::kRecorded;
    std::vector<WorkloadTrace> traces(benches.size()), other_traces;
    bool have_other = recorded;
    for (size_t i = 0; i < benches.size(); ++i) {
        auto t = makeSuiteBench(benches[i].name, frames, options.codec_model);
        if (!t)
            return makeError(t.error());
        traces[i] = std::move(*t);
        if (have_other) {
            auto o = makeSuiteBench(benches[i].name, frames, other_codec);
            if (o)
                other_traces.push_back(std::move(*o));
            else
                have_other = false;
        }
    }

    // The grid: every design at the default point (Fig. 12–14); Q-VR at every frequency ×
    // network (Table 4, Fig. 15); the local baseline at every frequency (Fig. 15's reference).
    std::vector<Job> jobs;
    for (size_t b = 0; b < benches.size(); ++b) {
        for (Design d : allDesigns())
            jobs.push_back({b, d, kDefaultMhz, "wifi", d == Design::Qvr});
        // Sensitivity: DFR with T_local measured from submission instead of GPU timestamps.
        jobs.push_back({b, Design::Dfr, kDefaultMhz, "wifi", false, true});
        // The other codec setting, every design at the default point.
        if (have_other)
            for (Design d : allDesigns())
                jobs.push_back({b, d, kDefaultMhz, "wifi", false, false, true});
        for (double mhz : kFreqsMhz) {
            for (const auto& net : kNets) {
                if (mhz == kDefaultMhz && net == "wifi")
                    continue;
                jobs.push_back({b, Design::Qvr, mhz, net, false});
            }
            if (mhz != kDefaultMhz)
                jobs.push_back({b, Design::Local, mhz, "wifi", false});
        }
    }

    for (const auto& net : trace_nets)
        for (size_t b = 0; b < benches.size(); ++b)
            for (Design d : trace_designs)
                jobs.push_back({b, d, kDefaultMhz, net, false});

    // Hardware at each clock, from the defaults or the user's overrides.
    std::map<double, HardwareConfig> hardware;
    for (const Job& job : jobs) {
        if (hardware.count(job.gpu_mhz))
            continue;
        if (options.hardware_path.empty()) {
            hardware[job.gpu_mhz] = defaultHardware(job.gpu_mhz);
        } else {
            auto hw = loadHardwareConfig(options.hardware_path, job.gpu_mhz);
            if (!hw)
                return makeError(hw.error());
            hardware[job.gpu_mhz] = *hw;
        }
    }

    std::vector<JobResult> results(jobs.size());
    std::atomic<size_t> next{0};
    std::atomic<int> done{0};
    std::mutex progress_mutex;
    std::mutex error_mutex;
    std::string first_error;
    auto worker = [&]() {
        for (;;) {
            const size_t i = next.fetch_add(1);
            if (i >= jobs.size())
                return;
            const Job& job = jobs[i];
            auto spec = networkSpecByName(job.net);
            std::unique_ptr<Link> link;
            if (spec) {
                // One noise sequence per bench × network, shared by every design.
                auto l =
                    makeLink(*spec, 1000 * (job.bench + 1) + static_cast<uint64_t>(job.net.size()));
                if (l)
                    link = std::move(*l);
            }
            if (!link) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (first_error.empty())
                    first_error = "cannot build network " + job.net;
                continue;
            }
            SimConfig cfg;
            cfg.bench = benches[job.bench].name;
            cfg.design = job.design;
            cfg.hardware = hardware.at(job.gpu_mhz);
            cfg.t_local_from_submission = job.from_submission;
            cfg.frames = options.frames;
            if (job.keep_frames)
                cfg.frames = frames;
            RunResult run =
                simulate(job.other_codec ? other_traces[job.bench] : traces[job.bench], cfg, *link);
            results[i].summary = run.summary;
            results[i].summary.design = variantName(results[i].summary.design, job.from_submission,
                                                    job.other_codec, other_codec);
            if (job.keep_frames)
                results[i].frames = std::move(run.frames);
            const int d = done.fetch_add(1) + 1;
            if (options.progress) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                options.progress(d, static_cast<int>(jobs.size()));
            }
        }
    };
    {
        std::vector<std::thread> pool;
        const int n_threads = std::min<int>(options.jobs, static_cast<int>(jobs.size()));
        for (int t = 0; t < n_threads; ++t)
            pool.emplace_back(worker);
        for (auto& t : pool)
            t.join();
    }
    if (!first_error.empty())
        return makeError(first_error);

    EvalOutput output;
    std::map<std::string, const JobResult*> by_key;
    for (size_t i = 0; i < jobs.size(); ++i) {
        output.runs.push_back(results[i].summary);
        const std::string design_key =
            variantName(traitsOf(jobs[i].design).name, jobs[i].from_submission, jobs[i].other_codec,
                        other_codec);
        by_key[key(benches[jobs[i].bench].name, design_key, jobs[i].gpu_mhz, jobs[i].net)] =
            &results[i];
    }
    auto get = [&](size_t b, Design d, double mhz = kDefaultMhz,
                   const std::string& net = "wifi") -> const RunSummary& {
        return by_key.at(key(benches[b].name, traitsOf(d).name, mhz, net))->summary;
    };
    const size_t nb = benches.size();
    const std::vector<Design> compared = {Design::Remote, Design::Static, Design::Ffr,
                                          Design::Dfr,    Design::Sw,     Design::Qvr};
    report::Plotter plotter(out, 1100, 520);
    // The title goes above the figure in report.html; the script's own titles (per panel) win
    // inside the image.
    auto plot = [&](const std::string& name, const std::string& title, const std::string& body) {
        if (plotter.plot(name, title, body))
            output.files.push_back(name + ".png");
        if (plotter.available())
            output.files.push_back(name + ".gp");
    };
    auto csv = [&](const std::string& name, const std::string& text) -> Status {
        output.files.push_back(name);
        return writeText(out / name, text);
    };

    // Fig. 12: end-to-end speedup over local; FPS of sw and qvr over local.
    std::string fig12 = "bench,label";
    for (Design d : compared)
        fig12 += fmt::format(",{}", traitsOf(d).name);
    fig12 += ",fps_sw_over_local,fps_qvr_over_local\n";
    std::map<Design, std::vector<double>> speedups;
    std::vector<double> fps_sw, fps_qvr, fps_qvr_over_static, fps_qvr_over_sw;
    for (size_t b = 0; b < nb; ++b) {
        const RunSummary& local = get(b, Design::Local);
        fig12 += fmt::format("{},{}", benches[b].name, benches[b].label);
        for (Design d : compared) {
            const double s = local.mtp_ms_mean / get(b, d).mtp_ms_mean;
            speedups[d].push_back(s);
            fig12 += fmtCell(s, 4);
        }
        const double fs = get(b, Design::Sw).fps_mean / local.fps_mean;
        const double fq = get(b, Design::Qvr).fps_mean / local.fps_mean;
        fps_sw.push_back(fs);
        fps_qvr.push_back(fq);
        fps_qvr_over_static.push_back(get(b, Design::Qvr).fps_mean /
                                      get(b, Design::Static).fps_mean);
        fps_qvr_over_sw.push_back(get(b, Design::Qvr).fps_mean / get(b, Design::Sw).fps_mean);
        fig12 += fmt::format(",{},{}\n", fmtNum(fs, 4), fmtNum(fq, 4));
    }
    if (auto st = csv("fig12_speedup.csv", fig12); !st)
        return makeError(st.error());
    plot("fig12", "Fig. 12: end-to-end speedup over local (x), FPS over local (x)",
         "set datafile separator ','\nset key autotitle columnheader\nset title 'Fig. 12: "
         "end-to-end speedup over local (500 MHz, "
         "Wi-Fi)'\nset style data histogram\nset style histogram clustered gap 1\n"
         "set style fill solid 0.8 border -1\nset key outside right\nset ylabel 'speedup (x)'\n"
         "set y2label 'FPS over local (x)'\nset y2tics\nset ytics nomirror\nset grid ytics\n"
         "plot for [i=3:8] 'fig12_speedup.csv' using i:xtic(2) title columnheader(i), "
         "'' using 0:9 with linespoints lw 2 axes x1y2 title 'SW-FPS', "
         "'' using 0:10 with linespoints lw 2 axes x1y2 title 'Q-VR-FPS'\n");

    // Fig. 13: transmitted data and shaded resolution normalised to remote.
    std::string fig13 = "bench,label";
    for (Design d : compared)
        fig13 += fmt::format(",data_{}", traitsOf(d).name);
    for (Design d : compared)
        fig13 += fmt::format(",pixels_{}", traitsOf(d).name);
    fig13 += "\n";
    std::vector<double> data_qvr_over_static, pixels_qvr;
    for (size_t b = 0; b < nb; ++b) {
        const RunSummary& remote = get(b, Design::Remote);
        fig13 += fmt::format("{},{}", benches[b].name, benches[b].label);
        for (Design d : compared)
            fig13 += fmtCell(get(b, d).bytes_per_frame_mean / remote.bytes_per_frame_mean, 4);
        for (Design d : compared)
            fig13 += fmtCell(get(b, d).pixels_per_frame_mean / remote.pixels_per_frame_mean, 4);
        fig13 += "\n";
        data_qvr_over_static.push_back(get(b, Design::Qvr).bytes_per_frame_mean /
                                       get(b, Design::Static).bytes_per_frame_mean);
        pixels_qvr.push_back(get(b, Design::Qvr).pixels_per_frame_mean /
                             remote.pixels_per_frame_mean);
    }
    if (auto st = csv("fig13_data_resolution.csv", fig13); !st)
        return makeError(st.error());
    plot("fig13", "Fig. 13: transmitted data and shaded resolution, normalised to remote (x)",
         "set datafile separator ','\nset multiplot layout 1,2 title 'Fig. 13: normalised to "
         "remote (500 MHz, Wi-Fi)'\nset style data histogram\nset style histogram clustered gap "
         "1\nset style fill solid 0.8 border -1\nset key top left font ',8'\nset grid ytics\n"
         "set title 'transmitted data'\nplot for [i=3:8] 'fig13_data_resolution.csv' using "
         "i:xtic(2) title columnheader(i)\nset title 'shaded resolution'\nplot for [i=9:14] "
         "'fig13_data_resolution.csv' using i:xtic(2) title columnheader(i)\nunset multiplot\n");

    // Fig. 14: latency ratio and FPS over 300 frames from e1 = 5°.
    {
        std::string ratio = "frame", fpsf = "frame";
        for (const auto& b : benches) {
            ratio += "," + b.label;
            fpsf += "," + b.label;
        }
        ratio += "\n";
        fpsf += "\n";
        for (int f = 0; f < kFig14Frames; ++f) {
            ratio += std::to_string(f);
            fpsf += std::to_string(f);
            for (size_t b = 0; b < nb; ++b) {
                const auto& fr =
                    by_key.at(key(benches[b].name, "qvr", kDefaultMhz, "wifi"))->frames;
                const FrameRecord* r =
                    f < static_cast<int>(fr.size()) ? &fr[static_cast<size_t>(f)] : nullptr;
                ratio += r ? fmtCell(r->latency_ratio, 4) : std::string(",");
                fpsf += r ? fmtCell(r->fps, 2) : std::string(",");
            }
            ratio += "\n";
            fpsf += "\n";
        }
        if (auto st = csv("fig14_latency_ratio.csv", ratio); !st)
            return makeError(st.error());
        if (auto st = csv("fig14_fps.csv", fpsf); !st)
            return makeError(st.error());
        plot("fig14",
             "Fig. 14: latency ratio T_remote/T_local and FPS over 300 frames from e1 = 5 deg",
             fmt::format("set datafile separator ','\nset multiplot layout 1,2 title 'Fig. 14: "
                         "Q-VR over {} frames from e1 = 5 deg (500 MHz, Wi-Fi)'\nset key top "
                         "right font ',8'\nset grid\nset xlabel 'frame'\nset title '(a) latency "
                         "ratio T_remote/T_local'\nset logscale y\nplot for [i=2:{}] "
                         "'fig14_latency_ratio.csv' using 1:i with lines title columnheader(i)\n"
                         "unset logscale y\nset title '(b) FPS'\nplot for [i=2:{}] "
                         "'fig14_fps.csv' using 1:i with lines title columnheader(i), 90 with "
                         "lines dt 2 lc rgb 'black' title '90 Hz'\nunset multiplot\n",
                         kFig14Frames, nb + 1, nb + 1));
    }

    // Table 4: steady-state e1 per bench × frequency × network; '*' marks < 90 FPS.
    std::string t4 = "gpu_mhz,net";
    for (const auto& b : benches)
        t4 += "," + b.label;
    for (const auto& b : benches)
        t4 += "," + b.label + "_meets_90hz";
    t4 += "\n";
    std::string t4_plot = "config";
    for (const auto& b : benches)
        t4_plot += "," + b.label;
    t4_plot += "\n";
    for (double mhz : kFreqsMhz) {
        for (const auto& net : kNets) {
            t4 += fmt::format("{},{}", static_cast<int>(mhz), net);
            t4_plot += fmt::format("{}MHz-{}", static_cast<int>(mhz), net);
            for (size_t b = 0; b < nb; ++b) {
                t4 += fmtCell(get(b, Design::Qvr, mhz, net).e1_deg_steady, 1);
                t4_plot += fmtCell(get(b, Design::Qvr, mhz, net).e1_deg_steady, 1);
            }
            for (size_t b = 0; b < nb; ++b)
                t4 += get(b, Design::Qvr, mhz, net).meets_refresh ? ",1" : ",0";
            t4 += "\n";
            t4_plot += "\n";
        }
    }
    if (auto st = csv("table4_e1.csv", t4); !st)
        return makeError(st.error());
    if (auto st = csv("table4_plot.csv", t4_plot); !st)
        return makeError(st.error());
    plot("table4", "Table 4: steady-state e1 (deg) of Q-VR",
         fmt::format("set datafile separator ','\nset title 'Table 4: steady-state e1 (deg) of "
                     "Q-VR'\nset style data histogram\nset style histogram clustered gap 1\n"
                     "set style fill solid 0.8 border -1\nset key outside right\nset xtics "
                     "rotate by -30\nset grid ytics\nset ylabel 'e1 (deg)'\nplot for [i=2:{}] "
                     "'table4_plot.csv' using i:xtic(1) title columnheader(i)\n",
                     nb + 1));

    // Fig. 15: Q-VR energy normalised to local at the same frequency, per network.
    std::string f15 = "config";
    for (const auto& b : benches)
        f15 += "," + b.label;
    f15 += ",mean\n";
    std::vector<double> energy_ratios;
    for (double mhz : kFreqsMhz) {
        for (const auto& net : kNets) {
            f15 += fmt::format("{}MHz-{}", static_cast<int>(mhz), net);
            std::vector<double> row;
            for (size_t b = 0; b < nb; ++b) {
                const double e = get(b, Design::Qvr, mhz, net).energy_mj_per_frame /
                                 get(b, Design::Local, mhz, "wifi").energy_mj_per_frame;
                row.push_back(e);
                energy_ratios.push_back(e);
                f15 += fmtCell(e, 4);
            }
            f15 += fmtCell(mean(row), 4) + "\n";
        }
    }
    if (auto st = csv("fig15_energy.csv", f15); !st)
        return makeError(st.error());
    plot("fig15", "Fig. 15: Q-VR energy per frame normalised to local (x)",
         fmt::format("set datafile separator ','\nset title 'Fig. 15: Q-VR energy per frame "
                     "normalised to local'\nset style data histogram\nset style histogram "
                     "clustered gap 1\nset style fill solid 0.8 border -1\nset key outside "
                     "right\nset xtics rotate by -30\nset grid ytics\nset ylabel 'energy / local "
                     "energy (x)'\nplot for [i=2:{}] 'fig15_energy.csv' using i:xtic(1) title "
                     "columnheader(i)\n",
                     nb + 2));

    // Trace-driven LTE: Q-VR, DFR and FFR on each Mahimahi trace rescaled to 100 Mbps.
    if (!trace_nets.empty()) {
        std::string mm =
            "trace,bench,label,design,mtp_ms_mean,mtp_ms_p99,fps_mean,e1_deg_steady,"
            "latency_ratio_final\n";
        std::string mm_plot = "trace";
        for (Design d : trace_designs)
            mm_plot += fmt::format(",{}_mean,{}_p99", traitsOf(d).name, traitsOf(d).name);
        mm_plot += "\n";
        for (const auto& net : trace_nets) {
            const std::string trace_name = fs::path(net.substr(6)).stem().string();
            std::map<Design, std::vector<double>> means, p99s;
            for (size_t b = 0; b < nb; ++b) {
                for (Design d : trace_designs) {
                    const RunSummary& r = get(b, d, kDefaultMhz, net);
                    means[d].push_back(r.mtp_ms_mean);
                    p99s[d].push_back(r.mtp_ms_p99);
                    mm += fmt::format("{},{},{},{},{:.3f},{:.3f},{:.2f},{:.2f},{:.3f}\n",
                                      trace_name, benches[b].name, benches[b].label,
                                      traitsOf(d).name, r.mtp_ms_mean, r.mtp_ms_p99, r.fps_mean,
                                      r.e1_deg_steady, r.latency_ratio_final);
                }
            }
            mm_plot += trace_name;
            for (Design d : trace_designs)
                mm_plot += fmt::format(",{:.3f},{:.3f}", mean(means[d]), mean(p99s[d]));
            mm_plot += "\n";
        }
        if (auto st = csv("mahimahi_lte.csv", mm); !st)
            return makeError(st.error());
        if (auto st = csv("mahimahi_plot.csv", mm_plot); !st)
            return makeError(st.error());
        plot("mahimahi", "MTP (ms) on Mahimahi LTE traces rescaled to 100 Mbps",
             "set datafile separator ','\nset key autotitle columnheader\nset title 'MTP on "
             "Mahimahi LTE traces rescaled to 100 Mbps (mean of the suite; 500 MHz)'\nset style "
             "data histogram\nset style histogram clustered gap 1\nset style fill solid 0.8 "
             "border -1\nset key outside right\nset grid ytics\nset ylabel 'MTP (ms)'\nplot "
             "for [i=2:7] 'mahimahi_plot.csv' using i:xtic(1) title columnheader(i)\n");
    }

    // Headlines.
    output.headlines = {
        {"Q-VR end-to-end speedup over local (mean)", 3.4, mean(speedups[Design::Qvr]), "x"},
        {"Q-VR FPS over static (mean)", 4.1, mean(fps_qvr_over_static), "x"},
        {"Q-VR FPS over software Q-VR (mean)", 2.8, mean(fps_qvr_over_sw), "x"},
        {"Q-VR data reduction vs static", 85.0, 100.0 * (1.0 - mean(data_qvr_over_static)), "%"},
        {"Q-VR shaded-pixel reduction vs full frame", 41.0, 100.0 * (1.0 - mean(pixels_qvr)), "%"},
        {"Q-VR energy reduction vs local (all freq x net)", 73.0,
         100.0 * (1.0 - mean(energy_ratios)), "%"},
        {"FFR end-to-end speedup over local (mean)", 1.75, mean(speedups[Design::Ffr]), "x"},
        {"DFR speedup over FFR (mean)", 1.1,
         mean(speedups[Design::Dfr]) / mean(speedups[Design::Ffr]), "x"},
    };

    // Qualitative findings (§6), per bench, counted. The paper's chain qvr ≥ dfr ≥ ffr is
    // checked as its two links, since they fail or hold for different reasons.
    {
        int ok = 0;
        std::string bad;
        for (size_t b = 0; b < nb; ++b) {
            const double q = speedups[Design::Qvr][b], d = speedups[Design::Dfr][b],
                         f = speedups[Design::Ffr][b];
            if (q >= d && q >= f)
                ++ok;
            else
                bad += fmt::format(" {} (qvr {:.2f}, dfr {:.2f}, ffr {:.2f});", benches[b].label, q,
                                   d, f);
        }
        output.findings.push_back(
            {"qvr >= dfr and qvr >= ffr in end-to-end speedup", mostBenches(ok, nb),
             fmt::format("holds for {}/{} benches; means qvr {:.2f}x, dfr {:.2f}x, ffr {:.2f}x.{}",
                         ok, nb, mean(speedups[Design::Qvr]), mean(speedups[Design::Dfr]),
                         mean(speedups[Design::Ffr]), bad.empty() ? "" : " Fails:" + bad)});
    }
    {
        int ok = 0;
        std::string detail;
        for (size_t b = 0; b < nb; ++b) {
            const double d = speedups[Design::Dfr][b], f = speedups[Design::Ffr][b];
            if (d >= f)
                ++ok;
            detail += fmt::format(" {} {:.2f}/{:.2f};", benches[b].label, d, f);
        }
        output.findings.push_back(
            {"dfr >= ffr in end-to-end speedup", mostBenches(ok, nb),
             fmt::format("holds for {}/{} benches (dfr/ffr speedup:{}) mean ratio {:.3f}; see "
                         "'Where we differ' below",
                         ok, nb, detail,
                         mean(speedups[Design::Dfr]) / mean(speedups[Design::Ffr]))});
    }
    {
        int ok = 0, total = 0;
        std::string bad;
        for (double mhz : kFreqsMhz) {
            for (size_t b = 0; b < nb; ++b) {
                const double w = get(b, Design::Qvr, mhz, "wifi").e1_deg_steady;
                const double l = get(b, Design::Qvr, mhz, "lte").e1_deg_steady;
                const double g = get(b, Design::Qvr, mhz, "5g").e1_deg_steady;
                ++total;
                if (l >= w && w >= g)
                    ++ok;
                else
                    bad += fmt::format(" {}@{} (lte {:.1f}, wifi {:.1f}, 5g {:.1f});",
                                       benches[b].label, static_cast<int>(mhz), l, w, g);
            }
        }
        output.findings.push_back({"steady e1: LTE >= Wi-Fi >= 5G", mostCells(ok, total),
                                   fmt::format("holds for {}/{} bench x frequency cells.{}", ok,
                                               total, bad.empty() ? "" : " Fails:" + bad)});
    }
    {
        int ok = 0, total = 0;
        std::string bad;
        for (const auto& net : kNets) {
            for (size_t b = 0; b < nb; ++b) {
                const double e5 = get(b, Design::Qvr, 500, net).e1_deg_steady;
                const double e4 = get(b, Design::Qvr, 400, net).e1_deg_steady;
                const double e3 = get(b, Design::Qvr, 300, net).e1_deg_steady;
                ++total;
                if (e5 >= e4 && e4 >= e3)
                    ++ok;
                else
                    bad += fmt::format(" {}@{} (500: {:.1f}, 400: {:.1f}, 300: {:.1f});",
                                       benches[b].label, net, e5, e4, e3);
            }
        }
        output.findings.push_back({"lower GPU frequency gives a smaller e1", mostCells(ok, total),
                                   fmt::format("holds for {}/{} bench x network cells.{}", ok,
                                               total, bad.empty() ? "" : " Fails:" + bad)});
    }
    {
        const double r = mean(data_qvr_over_static);
        output.findings.push_back(
            {"qvr sends far fewer bytes than static (< 50%)", r < 0.5,
             fmt::format(
                 "qvr/static bytes = {:.3f} on average (max {:.3f})", r,
                 *std::max_element(data_qvr_over_static.begin(), data_qvr_over_static.end()))});
    }
    {
        // Fig. 14 converges: |T_remote/T_local - 1| < 0.15 by frame 30 and for >= 90% of the
        // frames after that. A bench that does not is named with the per-frame quantities that
        // keep it off balance (fig14_e1.csv has every frame's e1, T_local and T_remote).
        int ok = 0;
        std::string detail;
        std::string e1csv = "bench,frame,e1_deg,t_local_ms,t_remote_ms,ratio\n";
        for (size_t b = 0; b < nb; ++b) {
            const auto& fr = by_key.at(key(benches[b].name, "qvr", kDefaultMhz, "wifi"))->frames;
            const int n = std::min<int>(kFig14Frames, static_cast<int>(fr.size()));
            int first = -1, within = 0;
            double e1_min = 1e9, e1_max = 0.0, tl = 0.0, tr = 0.0, tr2 = 0.0, rr = 0.0, rr2 = 0.0;
            for (int f = 0; f < n; ++f) {
                const FrameRecord& r = fr[static_cast<size_t>(f)];
                const bool in = std::fabs(r.latency_ratio - 1.0) < 0.15;
                if (first < 0 && in)
                    first = f;
                if (first >= 0 && f > first && in)
                    ++within;
                if (f >= 30) {
                    e1_min = std::min(e1_min, r.e1_deg);
                    e1_max = std::max(e1_max, r.e1_deg);
                    tl += r.t_local_ms;
                    tr += r.t_remote_ms;
                    tr2 += r.t_remote_ms * r.t_remote_ms;
                    rr += r.latency_ratio;
                    rr2 += r.latency_ratio * r.latency_ratio;
                }
                e1csv += fmt::format("{},{},{},{},{},{}\n", benches[b].label, f,
                                     fmtNum(r.e1_deg, 3), fmtNum(r.t_local_ms, 3),
                                     fmtNum(r.t_remote_ms, 3), fmtNum(r.latency_ratio, 4));
            }
            const int rest = first >= 0 ? n - first - 1 : 0;
            const double frac = rest > 0 ? static_cast<double>(within) / rest : 0.0;
            const bool conv = first >= 0 && first < 30 && frac >= 0.9;
            if (conv)
                ++ok;
            detail += fmt::format(" {}: balanced from frame {}, {:.0f}% of the rest",
                                  benches[b].label, first, 100.0 * frac);
            if (!conv && n > 30) {
                // The spread LIWC cannot remove: the frame-to-frame variation of T_remote (the
                // 20 dB SNR link noise alone is 10% RMS) against the ratio's own spread.
                const double k = n - 30;
                const double tr_mean = tr / k, rr_mean = rr / k;
                const double tr_cv =
                    std::sqrt(std::max(0.0, tr2 / k - tr_mean * tr_mean)) / std::max(tr_mean, 1e-9);
                const double rr_sd = std::sqrt(std::max(0.0, rr2 / k - rr_mean * rr_mean));
                detail += fmt::format(
                    " (frames 30+: e1 {:.1f}-{:.1f} deg, mean T_local {:.2f} ms, T_remote {:.2f} "
                    "ms; T_remote varies {:.0f}% RMS frame to frame, the ratio {:.2f} +- {:.2f})",
                    e1_min, e1_max, tl / k, tr_mean, 100.0 * tr_cv, rr_mean, rr_sd);
            }
            detail += ";";
        }
        if (auto st = csv("fig14_e1.csv", e1csv); !st)
            return makeError(st.error());
        output.findings.push_back(
            {"Fig. 14 converges (|ratio - 1| < 0.15 by frame 30, >= 90% after)",
             ok == static_cast<int>(nb), fmt::format("{}/{} benches.{}", ok, nb, detail)});
    }

    if (auto st = writeSummaryJson((out / "summary.json").string(), output.runs); !st)
        return makeError(st.error());
    output.files.push_back("summary.json");

    output.plot_note = plotter.note();

    // report.html
    report::HtmlReport page("qvr eval",
                            ".bad{text-decoration:underline;color:#b00}.no{color:#b00}"
                            ".yes{color:#070}");
    page.heading(1, "Q-VR simulator evaluation");
    page.html(fmt::format(
        "<p>Command: <code>{}</code><br>Frames per run: {} (Q-VR at the default point: {}, of "
        "which Fig. 14 plots the first 300); runs: {}; {}.<br>{} Models and constants: "
        "docs/MODEL.md.</p>\n",
        report::htmlEscape(options.command_line), options.frames, frames, output.runs.size(),
        report::htmlEscape(output.plot_note), suiteDescription()));
    page.heading(2, "Headline figures: paper vs. this simulator");
    report::Table headlines({"metric", "paper", "ours"});
    for (const auto& h : output.headlines)
        headlines.row({h.metric, fmtNum(h.paper, 2) + h.unit, fmtNum(h.ours, 2) + h.unit});
    page.table(headlines);
    page.heading(2, "Qualitative findings");
    std::string findings = "<ul>";
    for (const auto& f : output.findings)
        findings += fmt::format("<li><b>{}</b>: <span class='{}'>{}</span> — {}</li>\n",
                                report::htmlEscape(f.name), f.holds ? "yes" : "no",
                                f.holds ? "holds" : "does not hold", report::htmlEscape(f.detail));
    page.html(findings + "</ul>\n");
    {
        // The measured mechanism behind DFR vs FFR, from this run's own numbers.
        std::vector<double> dfr_e1, dfr_wait, ffr_remote, ffr_local, qvr_e1, dfr_ts, dfr_ts_e1;
        std::vector<double> qvr_kb, remote_kb, static_kb, qvr_remote;
        for (size_t b = 0; b < nb; ++b) {
            qvr_kb.push_back(get(b, Design::Qvr).bytes_per_frame_mean / 1e3);
            remote_kb.push_back(get(b, Design::Remote).bytes_per_frame_mean / 1e3);
            static_kb.push_back(get(b, Design::Static).bytes_per_frame_mean / 1e3);
            qvr_remote.push_back(get(b, Design::Qvr).t_remote_ms_mean);
            dfr_e1.push_back(get(b, Design::Dfr).e1_deg_steady);
            dfr_wait.push_back(get(b, Design::Dfr).render_wait_ms_mean);
            ffr_remote.push_back(get(b, Design::Ffr).t_remote_ms_mean);
            ffr_local.push_back(get(b, Design::Ffr).t_local_ms_mean);
            qvr_e1.push_back(get(b, Design::Qvr).e1_deg_steady);
            const RunSummary& ts =
                by_key.at(key(benches[b].name, "dfr-submission", kDefaultMhz, "wifi"))->summary;
            dfr_ts.push_back(get(b, Design::Local).mtp_ms_mean / ts.mtp_ms_mean);
            dfr_ts_e1.push_back(ts.e1_deg_steady);
        }
        page.html(fmt::format(
            "<h2>Where we differ from the paper, and why</h2><ul>"
            "<li><b>DFR vs FFR.</b> The paper has DFR 1.1x over FFR; here DFR/FFR = {:.2f}. "
            "FFR at e1 = 5&deg; sends its periphery in {:.1f} ms against a T_local of {:.1f} ms "
            "(means over the suite). DFR's LIWC reads T_local as the paper's GPU timers would: "
            "from the GPU's first cycle on the frame, so preemption by composition/ATW counts "
            "and waiting behind a pass ({:.1f} ms per frame here) does not. DFR then settles at "
            "e1 {:.1f}&deg; (Q-VR: {:.1f}&deg; on the same frames). Measuring T_local from "
            "submission instead, waits included (a modelling choice we used before), LIWC "
            "charges the waits to triangles and shrinks the fovea: DFR e1 {:.1f}&deg;, DFR/FFR "
            "= {:.2f}.</li>"
            "<li><b>Magnitudes.</b> The layer plan (Eq. 1 with Guenter's MAR) leaves Q-VR "
            "{:.1f}% of the full frame's pixels to shade (the paper: 59%, i.e. 41% fewer) and a "
            "periphery of {:.1f} KB a frame ({} bytes) where the remote design sends {:.0f} KB and "
            "static {:.0f} KB. So T_remote stays at {:.1f} ms on Wi-Fi at the balance point, "
            "e1 settles low, and the gains over local and static are larger than the "
            "paper's.</li>"
            "<li><b>Energy by network.</b> Radio energy uses Huang et al.'s (MobiSys 2012) "
            "measured power models, where Wi-Fi's per-bit cost (138 nJ/bit) exceeds LTE's (71 "
            "nJ/bit) at our goodputs, so Q-VR on LTE is cheaper than on Wi-Fi; the paper's "
            "'higher throughput, less energy' holds only between LTE/Wi-Fi and 5G.</li>"
            "<li><b>FPS formula.</b> FPS follows the paper, min(1/T_GPU, 1/T_network); the "
            "UCA's own 4.3 ms per 1920x2160 stereo frame is not in it, so Q-VR's formula FPS "
            "exceeds what its display path sustains (fps_pipeline in summary.json).</li>"
            "</ul><p>Models, constants and their sources: docs/MODEL.md.</p>",
            mean(speedups[Design::Dfr]) / mean(speedups[Design::Ffr]), mean(ffr_remote),
            mean(ffr_local), mean(dfr_wait), mean(dfr_e1), mean(qvr_e1), mean(dfr_ts_e1),
            mean(dfr_ts) / mean(speedups[Design::Ffr]), 100.0 * mean(pixels_qvr), mean(qvr_kb),
            codecModelName(options.codec_model), mean(remote_kb), mean(static_kb),
            mean(qvr_remote)));
    }
    if (have_other) {
        // Both recorded codec settings at the default point (500 MHz, Wi-Fi): what the paper's
        // lossless streams (§2.3) change against our CRF 23 ones.
        std::string codec_csv =
            "bench,codec,static_bg_kb,static_t_remote_ms,remote_kb,qvr_kb,qvr_e1_steady,"
            "qvr_t_local_ms,qvr_t_remote_ms,qvr_speedup,dfr_speedup,ffr_speedup\n";
        page.heading(2, "Codec setting: the paper's lossless H.264 vs our streaming x264");
        page.html(fmt::format(
            "<p>This report uses <b>{}</b> bytes (<code>--codec-model</code>); the table runs "
            "every design at 500 MHz on Wi-Fi with both. Table 1's static backgrounds: 482-646 "
            "KB a frame, T_remote 28-38 ms on Wi-Fi.</p>\n",
            codecModelName(options.codec_model)));
        for (size_t b = 0; b < nb; ++b) {
            for (bool other : {false, true}) {
                const CodecModel m = other ? other_codec : options.codec_model;
                auto run = [&](Design d) -> const RunSummary& {
                    return by_key
                        .at(key(benches[b].name,
                                variantName(traitsOf(d).name, false, other, other_codec),
                                kDefaultMhz, "wifi"))
                        ->summary;
                };
                const double local = run(Design::Local).mtp_ms_mean;
                const WorkloadTrace& t = other ? other_traces[b] : traces[b];
                double bg = 0.0;
                for (const auto& f : t.frames)
                    bg += f.static_split.bg_bytes;
                bg /= std::max<size_t>(1, t.frames.size());
                const std::string row = fmt::format(
                    "{},{},{},{},{},{},{},{},{},{},{},{}", benches[b].label, codecModelName(m),
                    fmtNum(bg / 1e3, 1), fmtNum(run(Design::Static).t_remote_ms_mean, 2),
                    fmtNum(run(Design::Remote).bytes_per_frame_mean / 1e3, 1),
                    fmtNum(run(Design::Qvr).bytes_per_frame_mean / 1e3, 1),
                    fmtNum(run(Design::Qvr).e1_deg_steady, 1),
                    fmtNum(run(Design::Qvr).t_local_ms_mean, 2),
                    fmtNum(run(Design::Qvr).t_remote_ms_mean, 2),
                    fmtNum(local / run(Design::Qvr).mtp_ms_mean, 2),
                    fmtNum(local / run(Design::Dfr).mtp_ms_mean, 2),
                    fmtNum(local / run(Design::Ffr).mtp_ms_mean, 2));
                codec_csv += row + "\n";
            }
        }
        page.table(report::Table::fromCsv(codec_csv));
        page.html("<p>Data: codec_models.csv</p>\n");
        if (auto st = csv("codec_models.csv", codec_csv); !st)
            return makeError(st.error());
    }
    auto figure = [&](const std::string& title, const std::string& png, const std::string& csvs) {
        page.heading(2, title);
        if (std::find(output.files.begin(), output.files.end(), png) != output.files.end())
            page.image(png, title, 1100);
        page.html("<p>Data: " + csvs + "</p>\n");
    };
    auto table = [&](const std::string& csv_text) { page.table(report::Table::fromCsv(csv_text)); };
    figure("Fig. 12: end-to-end speedup over local, FPS over local", "fig12.png",
           "<a href='fig12_speedup.csv'>fig12_speedup.csv</a>");
    table(fig12);
    figure("Fig. 13: transmitted data and shaded resolution, normalised to remote", "fig13.png",
           "<a href='fig13_data_resolution.csv'>fig13_data_resolution.csv</a>");
    table(fig13);
    figure("Fig. 14: latency ratio and FPS over 300 frames from e1 = 5&deg;", "fig14.png",
           "<a href='fig14_latency_ratio.csv'>fig14_latency_ratio.csv</a>, "
           "<a href='fig14_fps.csv'>fig14_fps.csv</a>, <a href='fig14_e1.csv'>fig14_e1.csv</a> "
           "(every frame's e1, T_local, T_remote and ratio: what keeps the ratio off 1 is in "
           "its T_remote column, see the Fig. 14 finding above)");
    figure("Table 4: steady-state e1 (deg); underlined red = misses 90 FPS", "table4.png",
           "<a href='table4_e1.csv'>table4_e1.csv</a>");
    {
        // Table 4 without its meets-90-Hz columns; a cell that misses 90 FPS is marked.
        report::Table t4_table = report::Table::fromCsv(t4);
        std::vector<std::string> header = {"gpu_mhz", "net"};
        for (const auto& b : benches)
            header.push_back(b.label);
        report::Table shown(header);
        for (size_t r = 0; r < t4_table.rows(); ++r) {
            const std::vector<report::Cell>& cells = t4_table.rowAt(r);
            std::vector<report::Cell> row;
            for (size_t i = 0; i < 2 + nb && i < cells.size(); ++i) {
                const bool miss = i >= 2 && 2 + nb + (i - 2) < cells.size() &&
                                  cells[2 + nb + (i - 2)].text == "0";
                row.emplace_back(cells[i].text, miss ? "bad" : "");
            }
            shown.row(std::move(row));
        }
        page.table(shown);
    }
    figure("Fig. 15: Q-VR energy per frame normalised to local", "fig15.png",
           "<a href='fig15_energy.csv'>fig15_energy.csv</a>");
    table(f15);
    if (!trace_nets.empty()) {
        figure("Trace-driven links: MTP mean and p99 on Mahimahi LTE traces (rescaled to 100 Mbps)",
               "mahimahi.png", "<a href='mahimahi_lte.csv'>mahimahi_lte.csv</a>");
    } else {
        page.html("<p>No Mahimahi traces were given (<code>--mahimahi FILE...</code>).</p>\n");
    }
    page.heading(2, "All runs").html("<p><a href='summary.json'>summary.json</a></p>\n");
    if (auto st = page.write(out / "report.html"); !st)
        return makeError(st.error());
    output.files.push_back("report.html");
    return output;
}

}  // namespace qvr
