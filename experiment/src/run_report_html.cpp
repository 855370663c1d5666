// report.html and its figures, written from a RunOutcome.
#include <array>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "qvr/experiment/run_report.h"
#include "qvr/report/html_report.h"

namespace qvr::experiment {

namespace fs = std::filesystem;
using namespace qvr::runtime;

namespace {

std::string num(double v, int prec = 1) {
    return fmt::format("{:.{}f}", v, prec);
}

std::string fmtCell(const std::optional<double>& v, const char* fmt_spec) {
    if (!v)
        return "—";
    return fmt::format(fmt::runtime(fmt_spec), *v);
}

// The transport's and the handshake's counters: what an operator reads to see loss being
// repaired, or an attack — the server's (all designs' sessions together) and each design's
// headset's.
void countersHtml(report::HtmlReport& page, const RunOutcome& o) {
    page.heading(2, "Transport and security counters");
    report::Table st({"server", "count"});
    const std::pair<const char*, const char*> server_rows[] = {
        {"connections", "TCP connections accepted"},
        {"clients_accepted", "sessions (key proven)"},
        {"auth_failures", "handshakes failing the key"},
        {"handshake_timeouts", "handshake timeouts"},
        {"pending_evicted", "unauthenticated connections evicted (flood)"},
        {"refused_full", "connections refused: full"},
        {"idle_timeouts", "sessions ended idle"},
        {"protocol_errors", "protocol errors"},
        {"version_mismatches", "version refusals"},
        {"settings_refusals", "settings refusals (codec, profile)"},
        {"route_failures", "media ports unverified"},
        {"control_forged", "forged control messages"},
        {"control_replayed", "replayed control messages"},
        {"control_drops", "malformed control messages dropped"},
        {"nacks", "NACKs served"},
        {"packets_retransmitted", "packets retransmitted"},
        {"bytes_retransmitted", "bytes retransmitted"},
        {"retransmissions_refused", "retransmissions refused (budget)"},
        {"fec_frames", "stream frames with FEC parity"},
        {"fec_parity_bytes", "FEC parity bytes"},
        {"key_frame_requests", "key-frame requests served"}};
    const nlohmann::json& server = o.server_stats;
    for (const auto& [key, label] : server_rows)
        if (server.contains(key) && server[key].is_number())
            st.row({report::Cell(label, "", true), fmt::format("{}", server[key].get<double>())});
    page.table(st);
    report::Table ct({"design", "media forged", "media replayed", "media dropped (all reasons)",
                      "NACKs sent", "packets recovered by NACK", "FEC rebuilt stream frames",
                      "streams lost", "key-frame requests", "connects"});
    for (const DesignResult& d : o.designs) {
        const HeadsetStats& h = d.stats;
        ct.row(
            {d.name, fmt::format("{}", h.net.media_drops[net::WireError::kBadMac]),
             fmt::format("{}", h.net.media_drops[net::WireError::kReplayed]),
             fmt::format("{}", h.net.media_drops.total()), fmt::format("{}", h.net.assembler.nacks),
             fmt::format("{}", h.net.assembler.packets_recovered),
             fmt::format("{}", h.net.assembler.fec_recoveries), fmt::format("{}", h.streams_lost),
             fmt::format("{}", h.key_frame_requests + h.net.key_frame_requests_sent),
             fmt::format("{}", h.connects)});
    }
    page.table(ct);
}

void limitsHtml(report::HtmlReport& page, const RunOutcome& o) {
    page.heading(2, "What limits the frame rate");
    report::Table table({"design", "headset busy ms/frame (core 0)", "decision ms",
                         "fovea/local render ms", "UCA ms", "T_remote ms (server, core 1)",
                         "limit"});
    for (const DesignResult& d : o.designs) {
        if (!d.limits)
            continue;
        const DesignLimits& l = *d.limits;
        table.row({d.name, fmt::format("{:.1f}", l.headset_busy_ms),
                   fmt::format("{:.1f}", l.decision_ms), fmt::format("{:.1f}", l.local_ms),
                   fmt::format("{:.1f}", l.uca_ms), fmt::format("{:.1f}", l.t_remote_ms),
                   report::Cell(l.limit, "", true)});
    }
    page.table(table);
    page.paragraph(
        "Both sides run llvmpipe on one core each of this machine; the paper's "
        "premise is a mobile GPU on the headset and a far stronger server GPU. Frames in flight "
        "(two by default) let the server render frame n+1 while the headset finishes n, so a "
        "design runs at the pace of the slower side.");
}

// The designs by name, each name once (its last run): summary.json's "designs".
std::map<std::string, const DesignResult*> designsByName(const RunOutcome& o) {
    std::map<std::string, const DesignResult*> by_name;
    for (const DesignResult& d : o.designs)
        by_name[d.name] = &d;
    return by_name;
}

// One design's rows of the validation table.
std::string validationRows(const DesignResult& d) {
    struct Row {
        Metric metric;
        const char* label;
        const char* f;
    };
    const Row rows[] = {{Metric::kFps, "FPS", "{:.1f}"},
                        {Metric::kMtpMean, "MTP mean ms", "{:.1f}"},
                        {Metric::kMtpP99, "MTP p99 ms", "{:.1f}"},
                        {Metric::kBytes, "bytes/frame", "{:.0f}"},
                        {Metric::kE1, "e1 mean °", "{:.1f}"},
                        {Metric::kHeadsetBusy, "headset busy ms/frame", "{:.1f}"},
                        {Metric::kServerBusy, "server busy ms/served frame", "{:.1f}"}};
    std::string speed_line;
    if (d.prediction.speed)
        speed_line = fmt::format("<br><small>speed ×{:.3f} headset, ×{:.3f} server</small>",
                                 d.prediction.speed->headset, d.prediction.speed->server);
    const auto& at_speed = d.prediction.at_probe_speed;
    const auto& paper = d.prediction.paper_hardware;
    std::string h;
    bool first = true;
    for (const Row& r : rows) {
        const bool e1 = r.metric == Metric::kE1;
        const std::string err_cell = e1 ? fmtCell(d.error->e1_deg_abs, "{:+.1f}°")
                                        : fmtCell(d.error->pctOf(r.metric), "{:+.1f}%");
        std::optional<double> at_speed_err;
        if (at_speed && e1)
            at_speed_err = d.error_at_probe_speed->e1_deg_abs;
        else if (at_speed)
            at_speed_err = d.error_at_probe_speed->pctOf(r.metric);
        h += fmt::format(
            "<tr>{}<td style='text-align:left'>{}</td><td>{}</td><td>{}</td><td>{}</td>"
            "<td>{}</td><td>{}</td><td>{}</td></tr>\n",
            first ? fmt::format("<td rowspan='{}'>{}{}</td>", std::size(rows),
                                report::htmlEscape(d.name), speed_line)
                  : "",
            r.label, fmtCell(d.measured.value(r.metric), r.f),
            fmtCell(d.prediction.calibrated->metrics.value(r.metric), r.f), err_cell,
            fmtCell(at_speed ? at_speed->value(r.metric) : std::nullopt, r.f),
            fmtCell(at_speed_err, e1 ? "{:+.1f}°" : "{:+.1f}%"),
            fmtCell(paper ? paper->value(r.metric) : std::nullopt, r.f));
        first = false;
    }
    return h;
}

// What the validation table says the calibrated prediction is made of.
std::string calibrationNote(const RunOutcome& o) {
    const std::string speed =
        o.speed_note.empty()
            ? fmt::format(
                  "speed probes (a fixed headset and server frame) before and "
                  "after each design moved {:.0f}% (headset) and {:.0f}% (server) "
                  "over the run{}",
                  o.speed.spread_pct[0], o.speed.spread_pct[1],
                  o.speed.unsteady ? ": the machine was unsteady, and a design's FPS moves "
                                     "with it within the seconds it runs, which no probe "
                                     "between designs follows"
                                   : "")
            : o.speed_note;
    return o.calibration.note + "; workload: " + o.workload_source + "; " + speed;
}

const std::string kFpsE1Title =
    "Displayed FPS over the fovea size: the fixed sweep and where qvr (LIWC) and sw run";
const std::array<std::pair<std::string, std::string>, 4> kFigureTitles = {{
    {"e1", "Fovea size e1 per frame (deg)"},
    {"mtp", "Motion-to-photon latency per frame (ms)"},
    {"bytes", "Bytes received per frame (KB, log scale)"},
    {"scanout", "Interval between scan-outs (ms)"},
}};
const char* kQualityTitle = "Display error vs eccentricity: PSNR against a full render (dB)";
const char* kPlotCommon = "set datafile separator ','\nset key outside right\nset grid\n";

// The per-frame figures of every design, from its frames_<design>.csv.
void frameFigures(report::Plotter& plotter, const RunOutcome& o) {
    const std::string common = kPlotCommon;
    std::string e1_plot = common + "set xlabel 'frame'\nset ylabel 'e1 (deg)'\nplot ";
    std::string mtp_plot = common + "set xlabel 'frame'\nset ylabel 'motion-to-photon (ms)'\nplot ";
    std::string bytes_plot =
        common + "set xlabel 'frame'\nset ylabel 'KB per frame'\nset logscale y\nplot ";
    std::string ft_plot = common +
                          "prev=0\nset yrange [0:150]\nset xlabel 'frame'\nset ylabel "
                          "'scan-out interval (ms)'\nplot ";
    bool first = true;
    for (const DesignResult& d : o.designs) {
        const std::string f = fmt::format("frames_{}.csv", d.name);
        const std::string sep = first ? "" : ", ";
        // Columns (1-based, telemetryCsvHeader): 2 frame, 3 e1, 21 display_ns, 22 bytes, 31 mtp.
        e1_plot += fmt::format("{}'{}' every ::1 using 2:3 with lines title '{}'", sep, f, d.name);
        mtp_plot +=
            fmt::format("{}'{}' every ::1 using 2:31 with lines title '{}'", sep, f, d.name);
        bytes_plot += fmt::format("{}'{}' every ::1 using 2:($22/1000+0.001) with lines title '{}'",
                                  sep, f, d.name);
        ft_plot += fmt::format(
            "{}'{}' every ::1 using 2:(d=($21-prev)/1e6, prev=$21, d) with lines title '{}'", sep,
            f, d.name);
        first = false;
    }
    plotter.plot("e1", kFigureTitles[0].second, e1_plot + "\n");
    plotter.plot("mtp", kFigureTitles[1].second, mtp_plot + "\n");
    plotter.plot("bytes", kFigureTitles[2].second, bytes_plot + "\n");
    plotter.plot("scanout", kFigureTitles[3].second, ft_plot + "\n");
}

// The fixed sweep: displayed FPS over e1, with LIWC's (and sw's) operating point, into
// fps_vs_e1.csv; the number of fixed designs on it.
int sweepFigure(report::Plotter& plotter, const RunOutcome& o, const fs::path& out) {
    int fixed_points = 0;
    std::ofstream sweep(out / "fps_vs_e1.csv");
    sweep << "design,kind,e1_deg,fps,mtp_ms_p99\n";
    for (const DesignResult& d : o.designs) {
        const Design k = d.spec.design;
        const bool fixed = k == Design::Fixed || k == Design::Ffr;
        const bool adaptive = k == Design::Qvr || k == Design::Sw;
        if (!fixed && !adaptive)
            continue;
        fixed_points += fixed ? 1 : 0;
        sweep << fmt::format("{},{},{:.3f},{:.3f},{:.3f}\n", d.name, fixed ? "fixed" : d.name,
                             d.summary.e1_deg_mean, d.summary.fps_mean, d.summary.mtp_ms_p99);
    }
    sweep.close();
    if (fixed_points >= 2)
        plotter.plot(
            "fps_e1", kFpsE1Title,
            std::string(kPlotCommon) +
                "set xlabel 'e1 (deg): fixed designs, and the mean e1 of adaptive ones'\n"
                "set ylabel 'displayed FPS'\n"
                "plot 'fps_vs_e1.csv' every ::1 using (strcol(2) eq 'fixed' ? $3 : 1/0):4 "
                "with linespoints pt 7 title 'fixed e1', "
                "'' every ::1 using (strcol(2) eq 'qvr' ? $3 : 1/0):4 with points pt 9 ps 2.5 "
                "title 'qvr (LIWC)', "
                "'' every ::1 using (strcol(2) eq 'sw' ? $3 : 1/0):4 with points pt 5 ps 2 "
                "title 'sw'\n");
    return fixed_points;
}

// PSNR over eccentricity of every design measured, from its quality_<design>.csv.
void qualityFigure(report::Plotter& plotter, const RunOutcome& o, const fs::path& out) {
    std::string q_plot = std::string(kPlotCommon) +
                         "set xlabel 'eccentricity from the gaze (deg)'\nset ylabel 'PSNR (dB)'\n"
                         "plot ";
    bool any = false;
    for (const DesignResult& d : o.designs) {
        if (!d.quality)
            continue;
        const std::string f = fmt::format("quality_{}.csv", d.name);
        std::ofstream csv(out / f);
        csv << "eccentricity_deg,psnr_db\n";
        for (const auto& [deg, sn] : d.quality->psnr_by_ecc)
            csv << fmt::format("{},{:.3f}\n", deg, sn.first / sn.second);
        q_plot += fmt::format("{}'{}' every ::1 using 1:2 with linespoints title '{}'",
                              any ? ", " : "", f, d.name);
        any = true;
    }
    if (any)
        plotter.plot("quality", kQualityTitle, q_plot + "\n");
}

void settingHtml(report::HtmlReport& page, const RunOutcome& o) {
    page.heading(1, "qvr run");
    page.html("<p>" + report::htmlEscape(o.command) + "<br>" + report::htmlEscape(o.date) + ", " +
              report::htmlEscape(o.machine) + "</p>\n");
    page.html(fmt::format(
        "<p>Scene {}, {}×{} per eye at {} Hz, link <code>{}</code> (net's userspace emulator on "
        "the "
        "server's egress), {} frames per design, of which the first {} are each session's "
        "start-up (connection, first renders, key frames, the policy's first decisions; for a "
        "design that asks the server for layers, also every frame until the first of them is "
        "on screen: <code>warmup_frames</code> in summary.json): logged, "
        "but outside every statistic below (their worst MTP is <code>startup_mtp_ms_max</code> "
        "in summary.json and the table's last column). The headset (this process) is "
        "pinned to core {}, "
        "the server (a child <code>qvr server</code> process) to core {}. Motion-to-photon is pose "
        "sample → UCA output complete on the headset's "
        "steady clock.</p>\n",
        report::htmlEscape(o.scene), o.profile.width_px, o.profile.height_px, o.profile.refresh_hz,
        report::htmlEscape(o.net), o.frames_per_design, o.warmup_frames, o.client_core,
        o.server_core));
}

void designsHtml(report::HtmlReport& page, const RunOutcome& o) {
    report::Table table({"design", "FPS", "MTP mean ms", "MTP p99 ms", "KB/frame", "e1 mean °",
                         "T_local ms", "T_remote ms", "UCA ms", "displayed", "reused",
                         "start-up MTP max ms"});
    for (const DesignResult& d : o.designs) {
        const DesignSummary& s = d.summary;
        table.row({s.design, num(s.fps_mean), num(s.mtp_ms_mean), num(s.mtp_ms_p99),
                   num(s.bytes_per_frame_mean / 1e3), num(s.e1_deg_mean), num(s.t_local_ms_mean),
                   num(s.t_remote_ms_mean), num(s.uca_ms_mean), std::to_string(s.frames_displayed),
                   std::to_string(s.frames_reused), num(s.startup_mtp_ms_max)});
    }
    page.table(table);
    if (const auto bf = bestFixed(o.designs)) {
        std::string text = fmt::format(
            "Best fixed fovea in hindsight among those run: {} at {:.1f} FPS with its own layers "
            "(MTP p99 {:.1f} ms).",
            bf->design, bf->fps_mean, bf->mtp_ms_p99);
        std::map<std::string, double> over(bf->fps_over_best.begin(), bf->fps_over_best.end());
        for (const char* d : {"qvr", "sw"})
            if (over.count(d))
                text += fmt::format(" {} reaches {:.2f}x its FPS.", d, over[d]);
        page.paragraph(text);
    }
}

// Several headsets on the one server: each one's measurements per design, Jain's fairness index
// over their FPS and the server's render + encode time per headset-frame.
void headsetsHtml(report::HtmlReport& page, const RunOutcome& o) {
    if (o.headsets <= 1)
        return;
    page.heading(2, fmt::format("{} headsets on one server", o.headsets));
    page.paragraph(fmt::format(
        "Headset 0 runs in this process as every run's headset does; the others each in a "
        "process of their own, all pinned to the headset core {} and started together at headset "
        "0's first frame; {}{}. Jain's fairness index is (ΣFPS)² / (n·ΣFPS²): 1 "
        "when every headset has the same frame rate. The server time per headset-frame is its "
        "render, readback and encode time per frame it served while the headsets ran.",
        o.client_core,
        o.identical_workloads ? "every headset the same motion and gaze (--identical-workloads)"
                              : "each its own motion recording and gaze seed",
        o.headset_offset_ms > 0.0
            ? fmt::format(", headset k {:g} ms ahead of headset 0 per k (--headset-offset-ms)",
                          o.headset_offset_ms)
            : std::string()));
    report::Table t({"design", "headset", "motion", "seed", "FPS", "MTP p99 ms", "KB/frame",
                     "e1 mean °", "Jain's index (FPS)", "server ms per headset-frame"});
    for (const HeadsetsResult& r : o.headsets_by_design)
        for (const HeadsetOutcome& h : r.headsets) {
            const bool first = h.index == 0;
            const std::string motion = fs::path(h.workload.motion).stem().string();
            const std::string seed = std::to_string(h.workload.seed);
            const std::string jain = first ? num(r.jain_fairness_fps, 3) : "";
            const std::string server =
                first ? fmtCell(r.server_ms_per_headset_frame, "{:.2f}") : "";
            if (!h.error.empty()) {
                t.row({r.design, std::to_string(h.index), motion, seed, "failed: " + h.error, "",
                       "", "", jain, server});
                continue;
            }
            const DesignSummary& s = h.summary;
            t.row({r.design, std::to_string(h.index), motion, seed, num(s.fps_mean),
                   num(s.mtp_ms_p99), num(s.bytes_per_frame_mean / 1e3), num(s.e1_deg_mean), jain,
                   server});
        }
    page.table(t);
}

void paperHtml(report::HtmlReport& page, const RunOutcome& o) {
    page.heading(2, "Against the paper");
    const HeadlineRatios r = headlineRatios(o.designs);
    auto cell = [&](const std::optional<double>& v, double scale, int prec) -> std::string {
        return v ? num(*v * scale, prec) : "—";
    };
    report::Table t({"ratio", "measured", "paper", "simulator (paper hardware)"});
    t.row({"Q-VR FPS over local (x)", cell(r.qvr_fps_over_local, 1, 2),
           cell(HeadlineRatios::kPaperQvrFpsOverLocal, 1, 2),
           cell(r.sim_qvr_fps_over_local, 1, 2)});
    t.row({"Q-VR bytes saved vs remote (%)", cell(r.qvr_bytes_saved_vs_remote, 100, 1),
           cell(HeadlineRatios::kPaperQvrBytesSavedVsRemote, 100, 1),
           cell(r.sim_qvr_bytes_saved_vs_remote, 100, 1)});
    page.table(t);
}

void qualityHtml(report::HtmlReport& page, const RunOutcome& o, const fs::path& out,
                 const report::Plotter& plotter) {
    page.heading(2, "Image quality against a full-resolution render");
    bool any = false;
    for (const DesignResult& d : o.designs)
        any = any || d.quality.has_value();
    if (!any) {
        page.paragraph(o.quality_every > 0 ? "Not measured: " + o.quality_note
                                           : "Not measured (--quality-every 0).");
        return;
    }
    page.paragraph(fmt::format(
        "Every {}th displayed frame (at most 12 per design), after that design's run and "
        "off its measured clock: the left eye as the headset displayed it against the "
        "full-resolution render of the same frame (the shown frame's render pose, the same "
        "level of detail), timewarped and lens-mapped to the same display pose in double "
        "precision. PSNR over RGB and SSIM of luma (7×7 windows), averaged over the sampled "
        "frames, by eccentricity band of each frame's own plan: the fovea (e < e1), the "
        "Eq. 4 blend bands (2 texels of the coarser layer either side of e1 and e2), the "
        "middle and the outer layer; 99 dB stands for identical. It is a still-image "
        "measure: temporal flicker and crawling of the down-sampled periphery from frame to "
        "frame, which the eye is sensitive to there, are not captured.",
        o.quality_every));
    report::Table t({"design", "frames", "fovea dB", "fovea SSIM", "blend dB", "blend SSIM",
                     "middle dB", "middle SSIM", "outer dB", "outer SSIM", "all dB", "all SSIM"});
    for (const DesignResult& d : o.designs) {
        if (!d.quality)
            continue;
        const DesignQuality& q = *d.quality;
        std::vector<report::Cell> row = {d.name, std::to_string(q.frames)};
        for (size_t i = 0; i < 5; ++i) {
            row.emplace_back(q.counted[i] ? num(q.psnr_db[i]) : "—");
            row.emplace_back(q.counted[i] ? num(q.ssim[i], 3) : "—");
        }
        t.row(std::move(row));
    }
    page.table(t);
    if (plotter.available())
        page.figure(out, "quality", kQualityTitle, 1000);
}

}  // namespace

// Measured against the calibrated runtime model and the paper-hardware model, per design.
std::string validationHtml(const RunOutcome& o) {
    std::string h =
        "<h2>Measured against the simulator</h2>\n<p>Prediction for this run's frames. "
        "<b>calibrated</b>: the runtime pipeline model "
        "(docs/MODEL.md §8–12) with this machine's costs, " +
        report::htmlEscape(calibrationNote(o)) +
        ". <b>paper hardware</b>: the paper's pipeline on its modelled mobile GPU and server "
        "(the default of <code>qvr eval</code>), for reference, not this machine. <b>at the "
        "probes' speed</b>: the calibrated model with each design's costs at the machine's speed "
        "just before and after it (a speed probe, over the calibration's), for reference. "
        "Error = (predicted − measured) / measured.</p>\n<table><tr><th>design</th>"
        "<th>metric</th><th>measured</th><th>calibrated</th><th>error</th><th>at the "
        "probes' speed</th><th>error</th><th>paper hardware</th></tr>\n";
    for (const auto& [name, d] : designsByName(o))
        if (d->prediction.calibrated)
            h += validationRows(*d);
    h += "</table>\n";
    if (!o.sim_note.empty())
        h += "<p>" + report::htmlEscape(o.sim_note) + "</p>\n";
    return h;
}

}  // namespace qvr::experiment

namespace qvr::experiment {

void writeRunReport(const RunOutcome& o, const fs::path& out) {
    std::ofstream(out / "summary.json") << summaryJson(o).dump(2) << "\n";
    report::Plotter plotter(out, 1000, 420);
    frameFigures(plotter, o);
    const int fixed_points = sweepFigure(plotter, o, out);
    qualityFigure(plotter, o, out);

    report::HtmlReport page("qvr run");
    settingHtml(page, o);
    designsHtml(page, o);
    headsetsHtml(page, o);
    limitsHtml(page, o);
    countersHtml(page, o);
    page.html(validationHtml(o));
    paperHtml(page, o);
    if (plotter.available())
        for (const auto& [name, title] : kFigureTitles)
            page.figure(out, name, title, 1000);
    if (plotter.available() && fixed_points >= 2)
        page.figure(out, "fps_e1", kFpsE1Title, 1000);
    else
        page.paragraph(plotter.note());
    qualityHtml(page, o, out, plotter);
    page.paragraph("Timeline: " + o.trace_note +
                   ". Both processes read CLOCK_MONOTONIC of this machine, so the true offset "
                   "is 0; the estimate checks that the stamps agree.");
    page.paragraph("Video: " + o.video.note);
    if (fs::exists(out / "qvr_display.mp4"))
        page.video("qvr_display.mp4", "qvr_display_still.png", 1000);
    if (fs::exists(out / "qvr_display_still.png"))
        page.image("qvr_display_still.png", "a frame the headset displayed for qvr", 1000);
    if (auto st = page.write(out / "report.html"); !st)
        std::fprintf(stderr, "qvr run: %s\n", st.error().c_str());
}

}  // namespace qvr::experiment
