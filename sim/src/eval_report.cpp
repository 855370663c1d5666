// `qvr eval`'s outputs: the figures' CSV and gnuplot scripts (Fig. 12–15, Table 4, Mahimahi),
// Fig. 14's balance check, and report.html. Every number in the report's prose is computed
// from this run or quoted from the paper as the paper's.
#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "eval_internal.h"

namespace qvr::eval_detail {

namespace fs = std::filesystem;

namespace {

const std::vector<Design> kCompared = {Design::Remote, Design::Static, Design::Ffr,
                                       Design::Dfr,    Design::Sw,     Design::Qvr};

std::string benchHeader(const EvalRuns& runs, const std::string& first,
                        const std::string& suffix = "") {
    std::string s = first;
    for (const auto& b : runs.benches)
        s += "," + b.label + suffix;
    return s;
}

// A gnuplot script: the clustered histogram of columns 2 to last_column of csv, a cluster per
// row (a configuration, labelled by column 1).
std::string configHistogram(const std::string& title, const std::string& ylabel,
                            const std::string& csv, size_t last_column) {
    return fmt::format(
        "set datafile separator ','\nset title '{}'\nset style data histogram\nset style "
        "histogram clustered gap 1\nset style fill solid 0.8 border -1\nset key outside "
        "right\nset xtics rotate by -30\nset grid ytics\nset ylabel '{}'\nplot for [i=2:{}] "
        "'{}' using i:xtic(1) title columnheader(i)\n",
        title, ylabel, last_column, csv);
}

// ",<prefix><design>" for each compared design.
std::string designHeader(const std::string& prefix) {
    std::string s;
    for (Design d : kCompared)
        s += fmt::format(",{}{}", prefix, traitsOf(d).name);
    return s;
}

// Bench b's name and label, then value(summary) for each compared design, to 4 places.
template <typename Value>
std::string designRow(const EvalRuns& runs, size_t b, Value value) {
    std::string s = fmt::format("{},{}", runs.benches[b].name, runs.benches[b].label);
    for (Design d : kCompared)
        s += fmtCell(value(runs.at(b, d)), 4);
    return s;
}

}  // namespace

Outputs::Outputs(const fs::path& dir) : m_dir(dir), m_plotter(dir, 1100, 520) {}

Status Outputs::csv(const std::string& name, const std::string& text) {
    m_files.push_back(name);
    std::ofstream f(m_dir / name, std::ios::binary);
    f << text;
    if (!f)
        return makeError(fmt::format("cannot write '{}'", (m_dir / name).string()));
    return Status::success();
}

// The title goes above the figure in report.html; the script's own titles (per panel) win
// inside the image.
void Outputs::plot(const std::string& name, const std::string& title, const std::string& body) {
    if (m_plotter.plot(name, title, body))
        m_files.push_back(name + ".png");
    if (m_plotter.available())
        m_files.push_back(name + ".gp");
}

bool Outputs::has(const std::string& name) const {
    return std::find(m_files.begin(), m_files.end(), name) != m_files.end();
}

// Fig. 12: end-to-end speedup over local; FPS of sw and qvr over local.
Expected<std::string> writeFig12(const EvalRuns& runs, Outputs& out) {
    std::string fig12 =
        "bench,label" + designHeader("") + ",fps_sw_over_local,fps_qvr_over_local\n";
    for (size_t b = 0; b < runs.size(); ++b) {
        const RunSummary& local = runs.at(b, Design::Local);
        fig12 += designRow(runs, b,
                           [&](const RunSummary& s) { return local.mtp_ms_mean / s.mtp_ms_mean; });
        fig12 +=
            fmt::format(",{},{}\n", fmtNum(runs.at(b, Design::Sw).fps_mean / local.fps_mean, 4),
                        fmtNum(runs.at(b, Design::Qvr).fps_mean / local.fps_mean, 4));
    }
    if (Status st = out.csv("fig12_speedup.csv", fig12); !st)
        return makeError(st.error());
    out.plot("fig12", "Fig. 12: end-to-end speedup over local (x), FPS over local (x)",
             "set datafile separator ','\nset key autotitle columnheader\nset title 'Fig. 12: "
             "end-to-end speedup over local (500 MHz, Wi-Fi)'\nset style data histogram\nset "
             "style histogram clustered gap 1\nset style fill solid 0.8 border -1\nset key "
             "outside right\nset ylabel 'speedup (x)'\nset y2label 'FPS over local (x)'\nset "
             "y2tics\nset ytics nomirror\nset grid ytics\nplot for [i=3:8] 'fig12_speedup.csv' "
             "using i:xtic(2) title columnheader(i), '' using 0:9 with linespoints lw 2 axes "
             "x1y2 title 'SW-FPS', '' using 0:10 with linespoints lw 2 axes x1y2 title "
             "'Q-VR-FPS'\n");
    return fig12;
}

// Fig. 13: transmitted data and shaded resolution normalised to remote.
Expected<std::string> writeFig13(const EvalRuns& runs, Outputs& out) {
    std::string fig13 = "bench,label" + designHeader("data_") + designHeader("pixels_") + "\n";
    for (size_t b = 0; b < runs.size(); ++b) {
        const RunSummary& remote = runs.at(b, Design::Remote);
        fig13 += designRow(runs, b, [&](const RunSummary& s) {
            return s.bytes_per_frame_mean / remote.bytes_per_frame_mean;
        });
        for (Design d : kCompared)
            fig13 += fmtCell(runs.at(b, d).pixels_per_frame_mean / remote.pixels_per_frame_mean, 4);
        fig13 += "\n";
    }
    if (Status st = out.csv("fig13_data_resolution.csv", fig13); !st)
        return makeError(st.error());
    out.plot("fig13", "Fig. 13: transmitted data and shaded resolution, normalised to remote (x)",
             "set datafile separator ','\nset multiplot layout 1,2 title 'Fig. 13: normalised to "
             "remote (500 MHz, Wi-Fi)'\nset style data histogram\nset style histogram clustered "
             "gap 1\nset style fill solid 0.8 border -1\nset key top left font ',8'\nset grid "
             "ytics\nset title 'transmitted data'\nplot for [i=3:8] 'fig13_data_resolution.csv' "
             "using i:xtic(2) title columnheader(i)\nset title 'shaded resolution'\nplot for "
             "[i=9:14] 'fig13_data_resolution.csv' using i:xtic(2) title columnheader(i)\nunset "
             "multiplot\n");
    return fig13;
}

// Fig. 14: latency ratio and FPS over 300 frames from e1 = 5°.
Status writeFig14(const EvalRuns& runs, Outputs& out) {
    std::string ratio = benchHeader(runs, "frame") + "\n";
    std::string fpsf = ratio;
    for (int f = 0; f < kFig14Frames; ++f) {
        ratio += std::to_string(f);
        fpsf += std::to_string(f);
        for (size_t b = 0; b < runs.size(); ++b) {
            const auto& fr = runs.job(b, "qvr").frames;
            const FrameRecord* r =
                f < static_cast<int>(fr.size()) ? &fr[static_cast<size_t>(f)] : nullptr;
            ratio += r ? fmtCell(r->latency_ratio, 4) : std::string(",");
            fpsf += r ? fmtCell(r->fps, 2) : std::string(",");
        }
        ratio += "\n";
        fpsf += "\n";
    }
    if (Status st = out.csv("fig14_latency_ratio.csv", ratio); !st)
        return st;
    if (Status st = out.csv("fig14_fps.csv", fpsf); !st)
        return st;
    const size_t nb = runs.size();
    out.plot("fig14",
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
    return Status::success();
}

// Table 4: steady-state e1 per bench × frequency × network, and whether 90 FPS is met.
Expected<std::string> writeTable4(const EvalRuns& runs, Outputs& out) {
    std::string t4 = benchHeader(runs, "gpu_mhz,net") + benchHeader(runs, "", "_meets_90hz") + "\n";
    std::string t4_plot = benchHeader(runs, "config") + "\n";
    for (double mhz : kFreqsMhz) {
        for (const auto& net : kNets) {
            t4 += fmt::format("{},{}", static_cast<int>(mhz), net);
            t4_plot += fmt::format("{}MHz-{}", static_cast<int>(mhz), net);
            for (size_t b = 0; b < runs.size(); ++b) {
                const double e1 =
                    runs.at(b, Design::Qvr, Variant::kFaithful, mhz, net).e1_deg_steady;
                t4 += fmtCell(e1, 1);
                t4_plot += fmtCell(e1, 1);
            }
            for (size_t b = 0; b < runs.size(); ++b)
                t4 += runs.at(b, Design::Qvr, Variant::kFaithful, mhz, net).meets_refresh ? ",1"
                                                                                          : ",0";
            t4 += "\n";
            t4_plot += "\n";
        }
    }
    if (Status st = out.csv("table4_e1.csv", t4); !st)
        return makeError(st.error());
    if (Status st = out.csv("table4_plot.csv", t4_plot); !st)
        return makeError(st.error());
    out.plot("table4", "Table 4: steady-state e1 (deg) of Q-VR",
             configHistogram("Table 4: steady-state e1 (deg) of Q-VR", "e1 (deg)",
                             "table4_plot.csv", runs.size() + 1));
    return t4;
}

// Fig. 15: Q-VR energy normalised to local at the same frequency, per network.
Expected<std::string> writeFig15(const EvalRuns& runs, Outputs& out) {
    std::string f15 = benchHeader(runs, "config") + ",mean\n";
    for (double mhz : kFreqsMhz) {
        for (const auto& net : kNets) {
            f15 += fmt::format("{}MHz-{}", static_cast<int>(mhz), net);
            std::vector<double> row;
            for (size_t b = 0; b < runs.size(); ++b) {
                row.push_back(
                    runs.at(b, Design::Qvr, Variant::kFaithful, mhz, net).energy_mj_per_frame /
                    runs.at(b, Design::Local, Variant::kFaithful, mhz).energy_mj_per_frame);
                f15 += fmtCell(row.back(), 4);
            }
            f15 += fmtCell(mean(row), 4) + "\n";
        }
    }
    if (Status st = out.csv("fig15_energy.csv", f15); !st)
        return makeError(st.error());
    out.plot("fig15", "Fig. 15: Q-VR energy per frame normalised to local (x)",
             configHistogram("Fig. 15: Q-VR energy per frame normalised to local",
                             "energy / local energy (x)", "fig15_energy.csv", runs.size() + 2));
    return f15;
}

// Trace-driven LTE: Q-VR, DFR and FFR on each Mahimahi trace rescaled to 100 Mbps.
Status writeMahimahi(const EvalRuns& runs, Outputs& out) {
    if (runs.trace_nets.empty())
        return Status::success();
    const std::vector<Design> designs = {Design::Ffr, Design::Dfr, Design::Qvr};
    std::string mm =
        "trace,bench,label,design,mtp_ms_mean,mtp_ms_p99,fps_mean,e1_deg_steady,"
        "latency_ratio_final\n";
    std::string mm_plot = "trace";
    for (Design d : designs)
        mm_plot += fmt::format(",{}_mean,{}_p99", traitsOf(d).name, traitsOf(d).name);
    mm_plot += "\n";
    for (const auto& net : runs.trace_nets) {
        const std::string trace_name = fs::path(net.substr(6)).stem().string();
        std::map<Design, std::vector<double>> means, p99s;
        for (size_t b = 0; b < runs.size(); ++b) {
            for (Design d : designs) {
                const RunSummary& r = runs.at(b, d, Variant::kFaithful, kDefaultMhz, net);
                means[d].push_back(r.mtp_ms_mean);
                p99s[d].push_back(r.mtp_ms_p99);
                mm += fmt::format("{},{},{},{},{:.3f},{:.3f},{:.2f},{:.2f},{:.3f}\n", trace_name,
                                  runs.benches[b].name, runs.benches[b].label, traitsOf(d).name,
                                  r.mtp_ms_mean, r.mtp_ms_p99, r.fps_mean, r.e1_deg_steady,
                                  r.latency_ratio_final);
            }
        }
        mm_plot += trace_name;
        for (Design d : designs)
            mm_plot += fmt::format(",{:.3f},{:.3f}", mean(means[d]), mean(p99s[d]));
        mm_plot += "\n";
    }
    if (Status st = out.csv("mahimahi_lte.csv", mm); !st)
        return st;
    if (Status st = out.csv("mahimahi_plot.csv", mm_plot); !st)
        return st;
    out.plot("mahimahi", "MTP (ms) on Mahimahi LTE traces rescaled to 100 Mbps",
             "set datafile separator ','\nset key autotitle columnheader\nset title 'MTP on "
             "Mahimahi LTE traces rescaled to 100 Mbps (mean of the suite; 500 MHz)'\nset style "
             "data histogram\nset style histogram clustered gap 1\nset style fill solid 0.8 "
             "border -1\nset key outside right\nset grid ytics\nset ylabel 'MTP (ms)'\nplot "
             "for [i=2:7] 'mahimahi_plot.csv' using i:xtic(1) title columnheader(i)\n");
    return Status::success();
}

namespace {

constexpr int kSmoothFrames = 10;  // the trailing window of Fig. 14's smoothed ratio
constexpr double kBand = 0.15;     // |ratio − 1| below this is balanced
constexpr double kBalancedShare = 0.9;

// Σ T_remote / Σ T_local over the trailing window ending at frame f.
double smoothedRatio(const std::vector<FrameRecord>& fr, int f) {
    double local = 0.0, remote = 0.0;
    for (int k = std::max(0, f - kSmoothFrames + 1); k <= f; ++k) {
        local += fr[static_cast<size_t>(k)].t_local_ms;
        remote += fr[static_cast<size_t>(k)].t_remote_ms;
    }
    return local > 0.0 ? remote / local : 0.0;
}

struct Balance {
    int first = -1;      // first frame whose smoothed ratio is in band
    double share = 0.0;  // of frames 30..n−1 in band
};

Balance balanceOf(const std::vector<FrameRecord>& fr, int n) {
    Balance bal;
    int in = 0;
    for (int f = 0; f < n; ++f) {
        const bool ok = std::fabs(smoothedRatio(fr, f) - 1.0) < kBand;
        if (ok && bal.first < 0)
            bal.first = f;
        if (f >= 30 && ok)
            ++in;
    }
    bal.share = n > 30 ? static_cast<double>(in) / (n - 30) : 0.0;
    return bal;
}

}  // namespace

// Fig. 14 converges: Q-VR's smoothed ratio (Σ T_remote / Σ T_local over 10 frames) is within
// ±15% by frame 30 and stays there for 90% of the later frames — or, where even the oracle
// policy on the same link (same noise seed) cannot hold 90% over its frames 30–129, for as
// large a share as the oracle.
Expected<Finding> fig14Finding(const EvalRuns& runs, Outputs& out) {
    int ok = 0;
    std::string detail;
    std::string csv =
        "bench,frame,e1_deg,t_local_ms,t_remote_ms,ratio,smoothed_ratio,oracle_e1_deg,"
        "oracle_smoothed_ratio\n";
    for (size_t b = 0; b < runs.size(); ++b) {
        const auto& fr = runs.job(b, "qvr").frames;
        const auto& oracle = runs.job(b, "qvr-oracle").frames;
        const int n = std::min(kFig14Frames, static_cast<int>(fr.size()));
        const Balance q = balanceOf(fr, n);
        const Balance o = balanceOf(oracle, static_cast<int>(oracle.size()));
        const double bar = std::min(kBalancedShare, o.share);
        const bool conv = q.first >= 0 && q.first <= 30 && q.share >= bar;
        ok += conv ? 1 : 0;
        detail += fmt::format(
            " {}: in band from frame {}, {:.0f}% of frames 30+ (oracle {:.0f}%, "
            "bar {:.0f}%);",
            runs.benches[b].label, q.first, 100.0 * q.share, 100.0 * o.share, 100.0 * bar);
        for (int f = 0; f < n; ++f) {
            const FrameRecord& r = fr[static_cast<size_t>(f)];
            csv += fmt::format(
                "{},{},{},{},{},{},{},{},{}\n", runs.benches[b].label, f, fmtNum(r.e1_deg, 3),
                fmtNum(r.t_local_ms, 3), fmtNum(r.t_remote_ms, 3), fmtNum(r.latency_ratio, 4),
                fmtNum(smoothedRatio(fr, f), 4),
                f < static_cast<int>(oracle.size())
                    ? fmtNum(oracle[static_cast<size_t>(f)].e1_deg, 3)
                    : std::string(),
                f < static_cast<int>(oracle.size()) ? fmtNum(smoothedRatio(oracle, f), 4)
                                                    : std::string());
        }
    }
    if (Status st = out.csv("fig14_e1.csv", csv); !st)
        return makeError(st.error());
    return Finding{
        "Fig. 14 converges (10-frame smoothed ratio within 15% by frame 30 and for "
        ">= 90% of later frames, or as often as the oracle on the same link)",
        ok == static_cast<int>(runs.size()),
        fmt::format("{}/{} benches.{}", ok, runs.size(), detail)};
}

}  // namespace qvr::eval_detail
