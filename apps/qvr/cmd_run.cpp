// `qvr run`: a render server and a headset client on loopback, each pinned to its own core, run
// every design of the runtime over the same frames through net's link emulator (paper Fig. 4,
// §6.1 measured for real), then write summary.json, per-frame telemetry, report.html with
// gnuplot figures, the video the headset displayed for `qvr`, and `qvr sim`'s prediction for the
// workload recorded during the run.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/codec/mp4_writer.h"
#include "qvr/compose/png_io.h"
#include "qvr/compose/quality.h"
#include "qvr/compose/test_pattern.h"
#include "qvr/compose/warp.h"
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/host.h"
#include "qvr/experiment/scanout_recorder.h"
#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/net/link_emulator.h"
#include "qvr/render/camera.h"
#include "qvr/render/renderer.h"
#include "qvr/report/html_report.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/chrome_trace.h"
#include "qvr/runtime/cpu_share.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/server_process.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/workload_probe.h"
#include "qvr/scene/scene_loader.h"
#include "qvr/sim/hardware.h"
#include "qvr/sim/network.h"
#include "qvr/sim/runtime_model.h"
#include "qvr/sim/simulator.h"
#include "qvr/workload/trace_io.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

namespace fs = std::filesystem;
using namespace qvr::runtime;

struct RunOptions {
    std::string scene = "builtin:room";
    std::string motion = "default";
    std::string gaze = "model";
    std::string net = "wifi";
    std::string profile = "default";
    std::string designs = "local,remote,ffr,fixed:10,fixed:20,sw,qvr";
    std::string out = "qvr-run";
    std::string codec = "x264";
    int frames = 150;
    uint64_t seed = 1;
    double remote_timeout_ms = 250.0;
    bool video = true;
    bool fovea_border = true;
    bool quiet = false;
    int video_max_frames = 900;
    int quality_every = 15;  // every Nth displayed frame is measured against a full render
    bool one_pass_periphery = false;
    bool no_holes = false;
    double headset_share = 1.0;
    std::string ring_counts = "clusters";
    int pipeline_depth = 2;
    int warmup_frames = 10;  // each design's first frames: start-up, outside the statistics
    float lod_px = 1.0f;
    std::string hardware;      // a calibration (qvr calibrate --out); none: cached or measured
    bool recalibrate = false;  // measure even when a cached calibration exists
    std::string command_line;
};

// Progress on a terminal while a design runs (design, frame k of N, FPS so far), redrawn at
// most five times a second on stderr; forwards each frame to the sink it wraps (the video).
class ProgressDisplay final : public DisplaySink {
public:
    ProgressDisplay(std::string design, int frames, DisplaySink* inner)
        : m_design(std::move(design)),
          m_frames(frames),
          m_inner(inner),
          m_start(std::chrono::steady_clock::now()) {}
    ~ProgressDisplay() override { std::fputs("\r\033[K", stderr); }
    void onScanout(const FrameTelemetry& frame, const LayerPlan& plan,
                   const std::array<ImageRgba8, 2>& eyes) override {
        if (m_inner)
            m_inner->onScanout(frame, plan, eyes);
        ++m_shown;
        const auto now = std::chrono::steady_clock::now();
        if (now - m_last < std::chrono::milliseconds(200) && m_shown < m_frames)
            return;
        m_last = now;
        const double s = std::chrono::duration<double>(now - m_start).count();
        std::fprintf(stderr, "\r\033[K  %-6s frame %lld of %d  %5.1f fps so far", m_design.c_str(),
                     static_cast<long long>(frame.frame + 1), m_frames, s > 0 ? m_shown / s : 0.0);
        std::fflush(stderr);
    }

private:
    std::string m_design;
    int m_frames;
    DisplaySink* m_inner;
    std::chrono::steady_clock::time_point m_start;
    std::chrono::steady_clock::time_point m_last{};
    int m_shown = 0;
};

// Keeps every Nth displayed frame's left eye at full resolution, with what its reference needs
// after the run: the plan it showed, the frame whose layers it showed, and when UCA ran.
class QualitySampler final : public DisplaySink {
public:
    struct Sample {
        int64_t frame = 0;
        int64_t shown_frame = 0;
        int64_t pose_ns = 0;
        int64_t uca_start_ns = 0;
        LayerPlan plan;
        ImageRgba8 left;
    };
    // The samples' images come from `pool` (allocated and touched before the run, returned by
    // recycle()): a fresh 16 MB allocation inside the headset's loop cost every sampled frame
    // 40–90 ms on these KVM guests (first-touch page faults), for every design alike.
    QualitySampler(int every, size_t max_samples, DisplaySink* inner, std::vector<ImageRgba8>& pool)
        : m_every(every), m_max(max_samples), m_inner(inner), m_pool(pool) {}
    void onScanout(const FrameTelemetry& t, const LayerPlan& plan,
                   const std::array<ImageRgba8, 2>& eyes) override {
        if (m_inner)
            m_inner->onScanout(t, plan, eyes);
        if ((t.frame + 1) % m_every != 0 || m_samples.size() >= m_max || eyes[0].empty() ||
            t.pose_ns < 0 || t.uca_start_ns < 0 || m_pool.empty())
            return;
        ImageRgba8 left = std::move(m_pool.back());
        m_pool.pop_back();
        if (left.width() != eyes[0].width() || left.height() != eyes[0].height())
            left.resize(eyes[0].width(), eyes[0].height());
        std::memcpy(left.data(), eyes[0].data(), eyes[0].sizeBytes());
        m_samples.push_back({t.frame, t.shown_frame >= 0 ? t.shown_frame : t.frame, t.pose_ns,
                             t.uca_start_ns, plan, std::move(left)});
    }
    const std::vector<Sample>& samples() const { return m_samples; }
    // Gives the images back to the pool for the next design.
    void recycle() {
        for (Sample& s : m_samples)
            m_pool.push_back(std::move(s.left));
        m_samples.clear();
    }

private:
    int m_every;
    size_t m_max;
    DisplaySink* m_inner;
    std::vector<ImageRgba8>& m_pool;
    std::vector<Sample> m_samples;
};

// A design's display against the full-resolution render of the same frame, by band, averaged
// over the sampled frames (PSNR averaged in dB, capped at 99 dB for identical images).
struct DesignQuality {
    int frames = 0;
    std::array<double, 5> psnr_db{};  // fovea, blend, middle, outer, all
    std::array<double, 5> ssim{};
    std::array<int, 5> counted{};
    std::map<double, std::pair<double, int>> psnr_by_ecc;  // bin centre → (sum, n)
    double seconds = 0.0;
};

Expected<DesignQuality> measureDesignQuality(const std::vector<QualitySampler::Sample>& samples,
                                             const HmdProfile& profile, const HeadsetTraces& traces,
                                             Renderer& renderer) {
    DesignQuality q;
    const auto t0 = std::chrono::steady_clock::now();
    ImageRgba8 full;
    for (const QualitySampler::Sample& s : samples) {
        // The poses the headset used: the shown frame's content time for the render, and the
        // newest pose when UCA ran for the display (headset_client.cpp).
        const double frame_ms = 1000.0 / profile.refresh_hz;
        const Pose render_pose = poseAt(traces.motion, double(s.shown_frame) * frame_ms);
        const Pose display_pose = poseAt(
            traces.motion, double(s.frame) * frame_ms + double(s.uca_start_ns - s.pose_ns) * 1e-6);
        auto st = renderer.render(fullFrameView(profile, render_pose, Eye::kLeft), full);
        if (!st)
            return makeError("quality reference: " + st.error());
        const ImageRgbD truth = groundTruthWarp(profile, full, render_pose, display_pose);
        const BandQuality b =
            measureQualityBands(profile, s.plan, render_pose, display_pose, s.left, truth);
        const RegionQuality* bands[5] = {&b.fovea, &b.blend, &b.middle, &b.outer, &b.all};
        for (size_t i = 0; i < 5; ++i) {
            if (bands[i]->pixels == 0)
                continue;
            q.psnr_db[i] += std::min(bands[i]->psnr_db, 99.0);
            q.ssim[i] += bands[i]->ssim;
            ++q.counted[i];
        }
        for (const BandQuality::Bin& bin : b.by_eccentricity) {
            auto& [sum, n] = q.psnr_by_ecc[bin.center_deg];
            sum += std::min(bin.q.psnr_db, 99.0);
            ++n;
        }
        ++q.frames;
    }
    for (size_t i = 0; i < 5; ++i)
        if (q.counted[i] > 0) {
            q.psnr_db[i] /= q.counted[i];
            q.ssim[i] /= q.counted[i];
        }
    q.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return q;
}

nlohmann::json summaryJson(const DesignSummary& s, const HeadsetStats& st) {
    return {{"fps_mean", s.fps_mean},
            {"mtp_ms_mean", s.mtp_ms_mean},
            {"mtp_ms_p99", s.mtp_ms_p99},
            {"bytes_per_frame_mean", s.bytes_per_frame_mean},
            {"e1_deg_mean", s.e1_deg_mean},
            {"frames_displayed", s.frames_displayed},
            {"frames_reused", s.frames_reused},
            {"frames", s.frames},
            {"frames_fallback_local", s.frames_fallback_local},
            {"t_local_ms_mean", s.t_local_ms_mean},
            {"t_remote_ms_mean", s.t_remote_ms_mean},
            {"uca_ms_mean", s.uca_ms_mean},
            {"wall_s", s.wall_s},
            {"warmup_frames", s.warmup_frames},
            {"startup_mtp_ms_max", s.startup_mtp_ms_max},
            {"startup_unfinished", s.startup_unfinished},
            {"streams_decoded", st.streams_decoded},
            {"streams_lost", st.streams_lost},
            {"decode_failures", st.decode_failures},
            {"late_frames", st.late_frames},
            {"key_frame_requests", st.key_frame_requests + st.net.key_frame_requests_sent},
            {"fec_recoveries", st.net.assembler.fec_recoveries},
            {"fec_packets_recovered", st.net.assembler.fec_packets_recovered},
            {"nacks_sent", st.net.assembler.nacks},
            {"packets_recovered", st.net.assembler.packets_recovered},
            {"media_forged", st.net.media_drops[net::WireError::kBadMac]},
            {"media_replayed", st.net.media_drops[net::WireError::kReplayed]},
            {"media_drops", st.net.media_drops.total()},
            {"client_core", st.core}};
}

struct DesignRun {
    DesignSpec spec;
    HeadsetResult result;
    // The machine's speed just before and just after the design ran (calibration.h SpeedProbe).
    std::optional<SpeedSample> speed_before, speed_after;
    Design design() const { return spec.design; }
    std::string label() const { return spec.label(); }
};

// The transport's and the handshake's counters (issue 12): what an operator reads to see loss
// being repaired, or an attack — the server's (all designs' sessions together) and each design's
// headset's.
void countersHtml(report::HtmlReport& page, const std::vector<DesignRun>& runs,
                  const nlohmann::json& server) {
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
    for (const auto& [key, label] : server_rows)
        if (server.contains(key) && server[key].is_number())
            st.row({report::Cell(label, "", true), fmt::format("{}", server[key].get<double>())});
    page.table(st);
    report::Table ct({"design", "media forged", "media replayed", "media dropped (all reasons)",
                      "NACKs sent", "packets recovered by NACK", "FEC rebuilt stream frames",
                      "streams lost", "key-frame requests", "connects"});
    for (const DesignRun& r : runs) {
        const HeadsetStats& h = r.result.stats;
        ct.row(
            {r.label(), fmt::format("{}", h.net.media_drops[net::WireError::kBadMac]),
             fmt::format("{}", h.net.media_drops[net::WireError::kReplayed]),
             fmt::format("{}", h.net.media_drops.total()), fmt::format("{}", h.net.assembler.nacks),
             fmt::format("{}", h.net.assembler.packets_recovered),
             fmt::format("{}", h.net.assembler.fec_recoveries), fmt::format("{}", h.streams_lost),
             fmt::format("{}", h.key_frame_requests + h.net.key_frame_requests_sent),
             fmt::format("{}", h.connects)});
    }
    page.table(ct);
}

// What limits each design's frame rate on this machine: the headset's busy time per frame (its
// core) against the server's service time per frame (T_remote: render, encode, link, decode
// of the other core's work), and the headset's largest stage.
void limitsHtml(report::HtmlReport& page, const std::vector<DesignRun>& runs) {
    page.heading(2, "What limits the frame rate");
    report::Table table({"design", "headset busy ms/frame (core 0)", "decision ms",
                         "fovea/local render ms", "UCA ms", "T_remote ms (server, core 1)",
                         "limit"});
    for (const DesignRun& r : runs) {
        double busy = 0, decision = 0, local = 0, uca = 0, remote = 0;
        int n = 0, n_busy = 0, n_remote = 0;
        for (const FrameTelemetry& t : r.result.frames) {
            ++n;
            decision += double(t.decision_ns - t.pose_ns) * 1e-6;
            local += t.t_local_ms;
            uca += t.uca_ms;
            if (t.headset_busy_ms > 0) {
                busy += t.headset_busy_ms;
                ++n_busy;
            }
            if (t.remote_requested) {
                remote += t.t_remote_ms;
                ++n_remote;
            }
        }
        if (n == 0)
            continue;
        busy = n_busy ? busy / n_busy : 0;
        remote = n_remote ? remote / n_remote : 0;
        decision /= n;
        local /= n;
        uca /= n;
        std::string limit;
        if (remote > busy) {
            limit = "server: its render + encode per frame (T_remote) exceeds the headset's work";
        } else {
            const double top = std::max({decision, local, uca});
            const char* stage = top == local ? "the local render"
                                : top == uca ? "UCA"
                                             : "the decision (BVH ring counts)";
            limit = fmt::format("headset: busiest stage {}", stage);
        }
        table.row({r.label(), fmt::format("{:.1f}", busy), fmt::format("{:.1f}", decision),
                   fmt::format("{:.1f}", local), fmt::format("{:.1f}", uca),
                   fmt::format("{:.1f}", remote), report::Cell(limit, "", true)});
    }
    page.table(table);
    page.paragraph(
        "Both sides run llvmpipe on one core each of this machine; the paper's "
        "premise is a mobile GPU on the headset and a far stronger server GPU. Frames in flight "
        "(two by default) let the server render frame n+1 while the headset finishes n, so a "
        "design runs at the pace of the slower side.");
}

// The calibration the prediction uses: the file given, this machine's cached one, or a fresh
// measurement (written to the cache). Always measured before the run: no constant is fitted to
// the run it predicts.
struct CalibrationChoice {
    HardwareConfig hardware;
    std::string source;  // "file", "cached" or "measured"
    std::string path;
    double seconds = 0.0;
    std::string note;  // one sentence for the console and the report
};

// What `qvr run` calibrates (and probes the machine's speed) with: the run's scene, profile,
// codec and level of detail, on the headset's core.
CalibrateOptions runCalibrateOptions(const RunOptions& o) {
    CalibrateOptions co;
    co.scene = o.scene;  // the bits law and the render costs are the scene's
    co.profile = o.profile;
    co.codec = o.codec;
    co.lod_px = o.lod_px;
    co.core = 0;
    co.verbose = false;
    return co;
}

Expected<CalibrationChoice> chooseCalibration(const RunOptions& o) {
    CalibrationChoice c;
    if (!o.hardware.empty()) {
        auto hw = loadHardwareConfig(o.hardware, 500.0);
        if (!hw)
            return makeError("--hardware: " + hw.error());
        if (!hw->runtime_pipeline)
            return makeError("--hardware: " + o.hardware +
                             " is not a calibration (no [runtime] pipeline = \"runtime\"; "
                             "qvr calibrate --out FILE writes one)");
        c.hardware = *hw;
        c.source = "file";
        c.path = o.hardware;
        c.note = "calibration from " + o.hardware;
        return c;
    }
    CalibrateOptions co = runCalibrateOptions(o);
    const std::string cache = calibrationCachePath(co);
    if (!o.recalibrate && fs::exists(cache)) {
        auto hw = loadHardwareConfig(cache, 500.0);
        if (hw) {
            c.hardware = *hw;
            c.source = "cached";
            c.path = cache;
            c.note = "this machine's cached calibration " + cache +
                     " (qvr run --recalibrate to measure again)";
            return c;
        }
        std::fprintf(stderr, "qvr run: ignoring the cached calibration: %s\n", hw.error().c_str());
    }
    // In its own thread pinned to the headset's core, so this thread's mask (inherited by the
    // server process) stays whole.
    Expected<Calibration> cal = makeError("not run");
    std::thread t([&] { cal = runCalibration(co); });
    t.join();
    if (!cal)
        return makeError("calibration: " + cal.error());
    cal->command = "qvr run (calibrating first: qvr calibrate --scene " + o.scene + " --profile " +
                   o.profile + ")";
    std::error_code ec;
    fs::create_directories(fs::path(cache).parent_path(), ec);
    if (std::ofstream f(cache); f)
        f << cal->toToml();
    auto hw = parseHardwareConfig(cal->toToml(), "calibration", 500.0);
    if (!hw)
        return makeError("calibration: " + hw.error());
    c.hardware = *hw;
    c.source = "measured";
    c.path = cache;
    c.seconds = cal->seconds;
    c.note = fmt::format("calibrated now, before the run, in {:.1f} s (saved as {})", cal->seconds,
                         cache);
    return c;
}

// The runtime designs on the simulator's: fixed:E is FFR at E degrees.
bool simDesignOf(const std::string& name, Design& design, double& fixed_e1_deg) {
    if (name.rfind("fixed:", 0) == 0) {
        char* end = nullptr;
        const double e = std::strtod(name.c_str() + 6, &end);
        if (end == name.c_str() + 6 || *end != '\0' || !(e > 0))
            return false;
        design = Design::Ffr;
        fixed_e1_deg = e;
        return true;
    }
    auto d = qvr::designByName(name);
    if (!d)
        return false;
    design = *d;
    return true;
}

nlohmann::json predictionJson(double fps, double mtp, double mtp_p99, double bytes, double e1) {
    return {{"fps_mean", fps},
            {"mtp_ms_mean", mtp},
            {"mtp_ms_p99", mtp_p99},
            {"bytes_per_frame_mean", bytes},
            {"e1_deg_mean", e1}};
}

// Signed error of the prediction, percent of the measurement (null where it is 0).
nlohmann::json errorPctJson(const nlohmann::json& predicted, const nlohmann::json& measured) {
    nlohmann::json e = nlohmann::json::object();
    for (const char* k : {"fps_mean", "mtp_ms_mean", "mtp_ms_p99", "bytes_per_frame_mean",
                          "e1_deg_mean", "headset_busy_ms_mean", "server_busy_ms_mean"}) {
        const nlohmann::json& mv = measured.contains(k) ? measured[k] : nlohmann::json();
        const double m = mv.is_number() ? mv.get<double>() : 0.0;
        const bool predicts = predicted.contains(k) && predicted[k].is_number();
        const double p = predicts ? predicted[k].get<double>() : 0.0;
        e[k] = m != 0.0 && predicts ? nlohmann::json(100.0 * (p - m) / std::fabs(m))
                                    : nlohmann::json();
    }
    return e;
}

std::string fmtCell(const nlohmann::json& v, const char* fmt_spec) {
    if (!v.is_number())
        return "—";
    return fmt::format(fmt::runtime(fmt_spec), v.get<double>());
}

// Measured against the calibrated runtime model and the paper-hardware model, per design.
std::string validationHtml(const nlohmann::json& designs, const std::string& calibration_note,
                           const std::string& sim_note) {
    std::string h =
        "<h2>Measured against the simulator</h2>\n<p>Prediction for this run's frames. "
        "<b>calibrated</b>: the runtime pipeline model "
        "(docs/MODEL.md §8) with this machine's costs, " +
        report::htmlEscape(calibration_note) +
        ". <b>paper hardware</b>: the paper's pipeline on its modelled mobile GPU and server "
        "(the default of <code>qvr eval</code>), for reference, not this machine. <b>at the "
        "probes' speed</b>: the calibrated model with each design's costs at the machine's speed "
        "just before and after it (a speed probe, over the calibration's), for reference. "
        "Error = (predicted − measured) / measured.</p>\n<table><tr><th>design</th>"
        "<th>metric</th><th>measured</th><th>calibrated</th><th>error</th><th>at the "
        "probes' speed</th><th>error</th><th>paper hardware</th></tr>\n";
    struct Metric {
        const char* key;
        const char* label;
        const char* f;
    };
    const Metric metrics[] = {{"fps_mean", "FPS", "{:.1f}"},
                              {"mtp_ms_mean", "MTP mean ms", "{:.1f}"},
                              {"mtp_ms_p99", "MTP p99 ms", "{:.1f}"},
                              {"bytes_per_frame_mean", "bytes/frame", "{:.0f}"},
                              {"e1_deg_mean", "e1 mean °", "{:.1f}"},
                              {"headset_busy_ms_mean", "headset busy ms/frame", "{:.1f}"},
                              {"server_busy_ms_mean", "server busy ms/served frame", "{:.1f}"}};
    for (auto it = designs.begin(); it != designs.end(); ++it) {
        const nlohmann::json& d = it.value();
        if (!d.contains("predicted"))
            continue;
        bool first = true;
        for (const Metric& m : metrics) {
            const nlohmann::json& err = d["prediction_error_pct"][m.key];
            std::string err_cell = fmtCell(err, "{:+.1f}%");
            if (std::string(m.key) == "e1_deg_mean")
                err_cell = fmtCell(d["prediction_error_abs"]["e1_deg_mean"], "{:+.1f}°");
            const nlohmann::json paper =
                d.contains("predicted_paper_hardware")
                    ? d["predicted_paper_hardware"].value(m.key, nlohmann::json())
                    : nlohmann::json();
            const bool at_cal = d.contains("predicted_at_probe_speed");
            const nlohmann::json cal_speed =
                at_cal ? d["predicted_at_probe_speed"].value(m.key, nlohmann::json())
                       : nlohmann::json();
            const bool e1 = std::string(m.key) == "e1_deg_mean";
            const nlohmann::json cal_speed_err =
                !at_cal ? nlohmann::json()
                : e1    ? d.value("prediction_error_abs_at_probe_speed", nlohmann::json::object())
                           .value(m.key, nlohmann::json())
                     : d["prediction_error_pct_at_probe_speed"].value(m.key, nlohmann::json());
            std::string speed_line;
            if (const auto& sp = d.value("speed", nlohmann::json::object());
                sp.contains("headset_factor"))
                speed_line = fmt::format("<br><small>speed ×{:.3f} headset, ×{:.3f} server</small>",
                                         sp["headset_factor"].get<double>(),
                                         sp["server_factor"].get<double>());
            h += fmt::format(
                "<tr>{}<td style='text-align:left'>{}</td><td>{}</td><td>{}</td><td>{}</td>"
                "<td>{}</td><td>{}</td><td>{}</td></tr>\n",
                first ? fmt::format("<td rowspan='{}'>{}{}</td>", std::size(metrics),
                                    report::htmlEscape(it.key()), speed_line)
                      : "",
                m.label, fmtCell(d.value(m.key, nlohmann::json()), m.f),
                fmtCell(d["predicted"].value(m.key, nlohmann::json()), m.f), err_cell,
                fmtCell(cal_speed, m.f), fmtCell(cal_speed_err, e1 ? "{:+.1f}°" : "{:+.1f}%"),
                fmtCell(paper, m.f));
            first = false;
        }
    }
    h += "</table>\n";
    if (!sim_note.empty())
        h += "<p>" + report::htmlEscape(sim_note) + "</p>\n";
    return h;
}

// Set by SIGINT/SIGTERM once the designs start: the current design ends at its next frame
// boundary, no further design starts, the server child is stopped (SIGTERM, so it writes its
// stats), and everything measured so far is written: summary.json, telemetry.csv, frames_*.csv,
// trace.json and the report for the designs run. The exit status is then 130.
std::atomic<bool> g_run_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

void onRunSignal(int) {
    g_run_stop.store(true);
}

int runRun(const RunOptions& o) {
    auto designs = parseDesignList(o.designs, DesignScope::Runtime);
    if (!designs) {
        std::fprintf(stderr, "qvr run: --designs: %s\n", designs.error().c_str());
        return 2;
    }
    if (o.frames < 2 || o.frames > 100000) {
        std::fprintf(stderr, "qvr run: --frames must be within 2..100000, got %d\n", o.frames);
        return 2;
    }
    if (o.warmup_frames < 0 || o.warmup_frames > o.frames - 2) {
        std::fprintf(stderr, "qvr run: --warmup-frames must be within 0..frames-2 (%d), got %d\n",
                     o.frames - 2, o.warmup_frames);
        return 2;
    }
    auto link = qvr::loadLinkSpec(o.net);
    if (!link) {
        std::fprintf(stderr, "qvr run: --net: %s\n", link.error().c_str());
        return 2;
    }
    auto profile = runtimeProfileByName(o.profile);
    if (!profile) {
        std::fprintf(stderr, "qvr run: --profile: %s\n", profile.error().c_str());
        return 2;
    }
    {
        CodecConfig codec;
        codec.backend = o.codec;
        if (auto st = validateCodecConfig(codec); !st) {
            std::fprintf(stderr, "qvr run: --codec: %s\n", st.error().c_str());
            return 2;
        }
    }
    if (std::string why; !makeOutputDir(o.out, why)) {
        std::fprintf(stderr, "qvr run: --out: %s\n", why.c_str());
        return 2;
    }
    const fs::path out(o.out);
    const auto t_start = std::chrono::steady_clock::now();
    auto inputs =
        loadHeadsetInputs(o.scene, o.motion, o.gaze, profile->refresh_hz, o.frames, o.seed);
    if (!inputs) {
        std::fprintf(stderr, "qvr run: %s\n", inputs.error().c_str());
        return 2;
    }
    auto calibration = chooseCalibration(o);
    if (!calibration) {
        std::fprintf(stderr, "qvr run: %s\n", calibration.error().c_str());
        return 2;
    }
    fmt::print("qvr run: prediction uses {}\n", calibration->note);
    const std::shared_ptr<const Scene>& scene = inputs->scene;
    const std::shared_ptr<const TriangleBvh>& bvh = inputs->bvh;
    const HeadsetTraces& traces = inputs->traces;

    // Two cores: the headset on core 0, the server's render thread on the last core.
    const int cores = onlineCores();
    const int client_core = 0;
    const int server_core = cores > 1 ? cores - 1 : -1;
    const net::PresharedKey key = net::PresharedKey::random();
    // The server is `qvr server` in a child process (server_process.h says why). Its key goes
    // through a file only it and we can read, removed once it is listening.
    auto exe = selfExecutable();
    if (!exe) {
        std::fprintf(stderr, "qvr run: %s\n", exe.error().c_str());
        return 1;
    }
    char key_path[] = "/tmp/qvr-run-key-XXXXXX";
    const int key_fd = mkstemp(key_path);
    if (key_fd < 0) {
        std::fprintf(stderr, "qvr run: cannot create a key file in /tmp\n");
        return 1;
    }
    const std::string key_hex = key.toHex() + "\n";
    const bool key_written =
        write(key_fd, key_hex.data(), key_hex.size()) == static_cast<ssize_t>(key_hex.size());
    close(key_fd);
    const fs::path server_stats_path = out / "server_stats.json";
    const fs::path server_stamps_path = out / "server_stamps.csv";
    std::vector<std::string> server_args = {"server",
                                            "--bind",
                                            "127.0.0.1",
                                            "--port",
                                            "0",
                                            "--key-file",
                                            key_path,
                                            "--scene",
                                            o.scene,
                                            "--profile",
                                            o.profile,
                                            "--net",
                                            o.net,
                                            "--codec",
                                            o.codec,
                                            "--core",
                                            std::to_string(server_core),
                                            "--stats-json",
                                            server_stats_path.string(),
                                            "--stamps-csv",
                                            server_stamps_path.string(),
                                            "--frames-csv",
                                            (out / "server_frames.csv").string(),
                                            "--lod-px",
                                            fmt::format("{}", o.lod_px)};
    if (o.one_pass_periphery)
        server_args.push_back("--one-pass-periphery");
    if (o.no_holes)
        server_args.push_back("--no-holes");
    auto server = key_written ? ServerProcess::start(*exe, server_args)
                              : Expected<ServerProcess>(makeError("cannot write the key file"));
    unlink(key_path);
    if (!server) {
        std::fprintf(stderr, "qvr run: %s\n", server.error().c_str());
        return 1;
    }
    // The headset's share of its core (CFS quota on this process; the server child was made
    // before, so it keeps its whole core).
    std::optional<CpuShareGroup> share_group;
    if (o.headset_share < 1.0) {
        auto g = CpuShareGroup::create(o.headset_share);
        Status moved = g ? g->addProcess(getpid()) : Status(makeError(g.error()));
        if (!moved) {
            std::fprintf(stderr, "qvr run: --headset-share %g refused: %s\n", o.headset_share,
                         moved.error().c_str());
            server->stop();
            return 2;
        }
        share_group = std::move(*g);
    }
    fmt::print(
        "qvr run: {} ({} triangles), {}x{} per eye at {} Hz, net {}, {} frames per design (the "
        "first {} start-up, outside the statistics)\n",
        scene->name, scene->triangleCount(), profile->width_px, profile->height_px,
        profile->refresh_hz, o.net, o.frames, o.warmup_frames);
    fmt::print(
        "  server on 127.0.0.1:{} pinned to core {}, headset pinned to core {} ({} cores){}\n",
        server->port(), server_core, client_core, cores,
        share_group
            ? fmt::format(", headset limited to {:.0f}% of its core (CFS quota "
                          "{:.1f} ms per 10 ms, {})",
                          100.0 * o.headset_share, 10.0 * o.headset_share, share_group->path())
            : std::string());

    // This thread, and every thread made while the designs run, on the headset's core: the
    // quality pass's renderer is made here, and once the first design's GL display is gone its
    // context makes llvmpipe's rasterizer threads, which the next designs' headsets then
    // share. Made on an unpinned thread they ran on the server's core as well: every design
    // after the first rendered its fovea on two cores (fixed:20's fovea 42 ms a frame after
    // ffr, 65 ms as the only design) and slowed the server's layers (docs/RUNTIME.md).
    std::optional<ScopedThreadPin> main_pin;
    if (client_core >= 0 && server_core >= 0) {
        main_pin.emplace(client_core);
        if (!main_pin->error().empty())
            std::fprintf(stderr, "qvr run: %s (the main thread runs unpinned)\n",
                         main_pin->error().c_str());
    }
    // The machine's speed before each design and after the last (calibration.h SpeedProbe), on
    // the headset's core while the server waits between sessions. The host's speed moves ±10%
    // from minute to minute (a calibration taken at a slow moment predicted every design of the
    // run after it 9-14% slow), and within seconds when it is unsteady: the run reports how far
    // the probes moved, warns above 10%, and puts beside the prediction a second one with each
    // design's costs at the ratio of the probes around it to the calibration's reference
    // (docs/MODEL.md §8 "The machine's speed at the run" says why it is not the prediction).
    const RuntimeCosts& calibrated = calibration->hardware.runtime;
    std::unique_ptr<SpeedProbe> speed_probe;
    std::string speed_note;
    if (calibrated.speed_reference_headset_ms <= 0.0 || calibrated.speed_reference_server_ms <= 0.0)
        speed_note =
            "the calibration has no speed reference (calibration version < 14): no speed "
            "probes";
    else if (calibrated.speed_reference_key != calibrationCacheKey(runCalibrateOptions(o)))
        speed_note =
            "the calibration's speed reference was taken on another machine, scene, profile, "
            "codec or level of detail than this run's: no speed probes";
    else if (o.headset_share < 1.0)
        speed_note =
            "--headset-share: a probe would run under the headset's quota: no speed probes";
    else if (auto made = SpeedProbe::make(runCalibrateOptions(o)); !made)
        speed_note = "no speed probes: " + made.error();
    else
        speed_probe = std::move(*made);
    auto probeSpeedNow = [&]() -> std::optional<SpeedSample> {
        if (!speed_probe)
            return std::nullopt;
        auto sample = speed_probe->measure();
        if (sample)
            return *sample;
        speed_note = "the speed probe failed: " + sample.error();
        speed_probe.reset();
        return std::nullopt;
    };
    std::vector<DesignRun> runs;
    std::unique_ptr<Renderer> quality_renderer;
    std::vector<std::pair<std::string, DesignQuality>> quality;
    std::string quality_note;
    ScanoutRecorder recorder(*profile, o.video_max_frames, o.fovea_border);
    ScanoutRecorder stand_in(*profile, o.video_max_frames, false, /*keep=*/false);
    // The quality samples' display images, allocated (and touched) once, before any run.
    constexpr size_t kQualitySamples = 12;
    std::vector<ImageRgba8> quality_pool;
    if (o.quality_every > 0)
        for (size_t k = 0; k < kQualitySamples; ++k)
            quality_pool.emplace_back(profile->width_px, profile->height_px);
    const fs::path workload_path = out / "workload.jsonl";
    bool recorded_workload = false;
    std::ofstream all_csv(out / "telemetry.csv");
    all_csv << telemetryCsvHeader();
    g_run_stop.store(false);
    std::signal(SIGINT, onRunSignal);
    std::signal(SIGTERM, onRunSignal);
    std::string interrupted_note;
    // Designs that asked for the server's layers and never showed one: their display was stale
    // throughout, so the run is reported as failed (exit 1) after everything is written.
    std::vector<std::string> never_shown;
    for (const DesignSpec& spec : *designs) {
        if (g_run_stop.load())
            break;
        const Design d = spec.design;
        const std::string label = spec.label();
        HeadsetConfig hc;
        hc.design = d;
        hc.fixed_e1_deg = spec.fixed_e1_deg;
        hc.profile = *profile;
        hc.codec.backend = o.codec;
        hc.port = server->port();
        hc.key = key;
        hc.frames = o.frames;
        hc.core = client_core;
        hc.remote_timeout_ms = o.remote_timeout_ms;
        hc.pipeline_depth = o.pipeline_depth;
        hc.warmup_frames = o.warmup_frames;
        hc.lod_error_px = o.lod_px;
        hc.cluster_ring_counts = o.ring_counts == "clusters";
        hc.stop = &g_run_stop;
        GlRendererOptions gl;
        gl.lod_error_px = o.lod_px;
        hc.renderer = glRendererFactory(gl);
        std::ofstream workload_out;
        std::unique_ptr<WorkloadTraceWriter> writer;
        if (d == Design::Qvr) {
            if (o.video) {
                recorder.reserve(o.frames);
                hc.display = &recorder;
            }
            // The qvr design probes its ring counts anyway; recording them costs it the write.
            // (Until 2026-11-27 the other designs recorded it, each overwriting the last, and
            // paid the probe, 0.3-0.5 ms a frame, that neither they nor the model charge.)
            workload_out.open(workload_path);
            if (workload_out) {
                writer = std::make_unique<WorkloadTraceWriter>(workload_out);
                hc.workload = writer.get();
                recorded_workload = true;
            }
        } else if (o.video) {
            stand_in.reserve(1);
            hc.display = &stand_in;
        }
        std::unique_ptr<QualitySampler> sampler;
        if (o.quality_every > 0) {
            sampler = std::make_unique<QualitySampler>(o.quality_every, kQualitySamples, hc.display,
                                                       quality_pool);
            hc.display = sampler.get();
        }
        std::unique_ptr<ProgressDisplay> progress;
        if (!o.quiet && isatty(STDERR_FILENO)) {
            progress = std::make_unique<ProgressDisplay>(label, o.frames, hc.display);
            hc.display = progress.get();
        }
        const std::optional<SpeedSample> speed_before = probeSpeedNow();
        if (!runs.empty())
            runs.back().speed_after = speed_before;  // the last design's "after"
        Expected<HeadsetResult> result = makeError("not run");
        std::thread headset([&] { result = runHeadset(hc, scene, bvh, traces); });
        headset.join();
        progress.reset();  // clears the progress line
        if (!result) {
            std::fprintf(stderr, "qvr run: %s: %s\n", label.c_str(), result.error().c_str());
            return 1;
        }
        const bool stopped = g_run_stop.load();
        if (stopped) {
            interrupted_note =
                fmt::format("interrupted during {} after {} of {} frames; {} of {} designs run",
                            label, result->frames.size(), o.frames,
                            runs.size() + (result->frames.empty() ? 0 : 1), designs->size());
            if (result->frames.empty())
                break;  // nothing measured for this design
        }
        const DesignSummary& s = result->summary;
        fmt::print(
            "  {:6} fps {:6.1f}  mtp {:6.1f} ms (p99 {:6.1f})  {:8.0f} B/frame  e1 {:5.1f} deg  "
            "displayed {} reused {}\n",
            s.design, s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean,
            s.e1_deg_mean, s.frames_displayed, s.frames_reused);
        if (s.startup_unfinished && o.warmup_frames > 0) {
            never_shown.push_back(label);
            fmt::print(
                "  warning: {}: the start-up never ended (none of the server's layers reached the "
                "screen in {} frames); its statistics are over every frame, not a steady state "
                "(summary.json startup_unfinished)\n",
                s.design, s.frames);
        }
        std::fflush(stdout);
        for (const FrameTelemetry& t : result->frames)
            all_csv << telemetryCsvRow(label, t);
        if (auto st = writeTelemetryCsv((out / fmt::format("frames_{}.csv", label)).string(), label,
                                        result->frames);
            !st)
            std::fprintf(stderr, "qvr run: %s\n", st.error().c_str());
        runs.push_back({spec, std::move(*result), speed_before, std::nullopt});
        if (stopped) {
            // No quality pass: the user asked to stop.
            if (quality.empty() && quality_note.empty())
                quality_note = "the run was interrupted before the quality pass";
            break;
        }
        // Image quality, between the measured runs: each sampled display against a
        // full-resolution render of the same frame (rendered now, on this thread).
        if (sampler && !sampler->samples().empty()) {
            if (!quality_renderer) {
                auto made = glRendererFactory(gl)();
                if (made && (*made)->upload(*scene))
                    quality_renderer = std::move(*made);
                else
                    quality_note = "no reference renderer: " +
                                   (made ? std::string("scene upload failed") : made.error());
            }
            if (quality_renderer) {
                auto q =
                    measureDesignQuality(sampler->samples(), *profile, traces, *quality_renderer);
                if (q)
                    quality.emplace_back(label, std::move(*q));
                else
                    quality_note = q.error();
            }
        }
        if (sampler)
            sampler->recycle();
        // Let the server finish the last session before the next one starts.
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    if (!g_run_stop.load() && !runs.empty())
        runs.back().speed_after = probeSpeedNow();
    // How far the machine's speed moved over the run: every probe's spread, per side. A host
    // that moves within a design (seconds) moves its FPS by as much, which no probe between
    // designs can follow; the run says so rather than let the error look like the model's.
    std::array<double, 2> speed_spread_pct{0.0, 0.0};  // headset, server: max / min − 1
    // The run's probes' mean over the calibration's reference, per side (0: no probes).
    std::array<double, 2> speed_over_reference{0.0, 0.0};
    {
        std::vector<SpeedSample> all;
        for (const DesignRun& r : runs)
            if (r.speed_before)
                all.push_back(*r.speed_before);
        if (!runs.empty() && runs.back().speed_after)
            all.push_back(*runs.back().speed_after);
        if (!all.empty() && calibrated.speed_reference_headset_ms > 0.0 &&
            calibrated.speed_reference_server_ms > 0.0) {
            for (const SpeedSample& p : all) {
                speed_over_reference[0] += p.headset_ms / double(all.size());
                speed_over_reference[1] += p.server_ms / double(all.size());
            }
            speed_over_reference[0] /= calibrated.speed_reference_headset_ms;
            speed_over_reference[1] /= calibrated.speed_reference_server_ms;
        }
        speed_spread_pct = speedProbesSpreadPct(all);
    }
    const bool unsteady = std::max(speed_spread_pct[0], speed_spread_pct[1]) > kUnsteadySpeedPct;
    // A second Ctrl-C while the report is written ends the process at once.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    const bool interrupted = g_run_stop.load();
    if (interrupted && interrupted_note.empty())
        interrupted_note = fmt::format("interrupted between designs; {} of {} designs run",
                                       runs.size(), designs->size());
    all_csv.flush();
    main_pin.reset();  // the report's work may use every core
    const int server_status = server->stop();
    nlohmann::json server_stats = nlohmann::json::object();
    if (std::ifstream f(server_stats_path); f) {
        server_stats = nlohmann::json::parse(f, nullptr, false);
        if (server_stats.is_discarded())
            server_stats = nlohmann::json::object();
    }
    if (server_status != 0)
        std::fprintf(stderr, "qvr run: the server exited with status %d\n", server_status);
    // trace.json: every design's headset stages and the server's, on the headset's clock.
    nlohmann::json trace_json = nlohmann::json::object();
    std::string trace_note;
    std::vector<ServerBusy> server_busy;  // per design, in the order of runs
    {
        std::vector<ServerFrameStamps> stamps;
        if (auto read = readServerStamps(server_stamps_path.string()))
            stamps = std::move(*read);
        else
            trace_note = "no server stages: " + read.error();
        std::vector<TraceDesign> tds;
        for (const DesignRun& r : runs)
            tds.push_back({r.label(), r.result.origin_ns, profile->refresh_hz, &r.result.frames});
        server_busy = serverBusyPerDesign(tds, stamps);
        if (auto info = writeChromeTrace((out / "trace.json").string(), tds, stamps)) {
            trace_json = {{"path", "trace.json"},
                          {"events", info->events},
                          {"frames", info->frames_written},
                          {"frames_left_out", info->frames_left_out},
                          {"server_frames", info->server_frames_matched},
                          {"server_offset_ms", info->offset.offset_ns * 1e-6},
                          {"server_offset_bound_ms", info->offset.bound_ns * 1e-6},
                          {"offset_requests", info->offset.requests}};
            trace_note = fmt::format(
                "trace.json ({} events; ui.perfetto.dev or chrome://tracing): server stamps put "
                "on the headset clock with offset {:+.3f} ms ± {:.3f} ms estimated from {} "
                "requests{}",
                info->events, info->offset.offset_ns * 1e-6, info->offset.bound_ns * 1e-6,
                info->offset.requests, trace_note.empty() ? "" : "; " + trace_note);
        } else {
            trace_note = "trace.json failed: " + info.error();
            std::fprintf(stderr, "qvr run: %s\n", trace_note.c_str());
        }
    }
    const double run_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();

    // What the simulators predict for the recorded workload: the runtime model with this
    // machine's calibration, and the paper's model on its modelled hardware.
    nlohmann::json predicted = nlohmann::json::object();        // design → runtime model
    nlohmann::json predicted_paper = nlohmann::json::object();  // design → paper model
    // design → the runtime model at the probes' speed, and the speed factors used
    nlohmann::json predicted_at_probe_speed = nlohmann::json::object();
    nlohmann::json speed_json = nlohmann::json::object();
    auto speedFactors = [&](const DesignRun& r) -> std::optional<std::pair<double, double>> {
        double h = 0.0, sv = 0.0;
        int n = 0;
        for (const std::optional<SpeedSample>& p : {r.speed_before, r.speed_after})
            if (p) {
                h += p->headset_ms;
                sv += p->server_ms;
                ++n;
            }
        if (n == 0 || calibrated.speed_reference_headset_ms <= 0.0 ||
            calibrated.speed_reference_server_ms <= 0.0)
            return std::nullopt;
        return std::make_pair(h / n / calibrated.speed_reference_headset_ms,
                              sv / n / calibrated.speed_reference_server_ms);
    };
    nlohmann::json sim_json = nlohmann::json::object();
    std::string sim_note;
    // The workload the predictions replay: every frame's triangles and pixels per ring as the
    // headset's LIWC counts them (the draw clusters at the fovea's level of detail, or the BVH
    // with --ring-counts bvh; all rings), computed here after the runs, off the clock, for the
    // same poses and gazes; bits per pixel from the calibration's codec law. The layers' render
    // costs are charged on the triangles each layer draws (level of detail, holes) for the same
    // poses and the plan the model chose, counted the same way off the clock
    // (render/renderer.h layerTriangles). So every design set gets a prediction and nothing in
    // it is measured on the run. Without a bits law in the calibration, the qvr run's recorded
    // workload (its bits per pixel as the headset estimated them) is used.
    const RuntimeCosts& rcosts = calibration->hardware.runtime;
    Expected<WorkloadTrace> trace = makeError("no workload");
    std::string trace_source;
    size_t bits_frames_own = 0;  // predicted frames charged the calibration's own bits for them
    auto draw_list = std::make_shared<DrawList>(buildDrawList(*scene));
    if (o.lod_px > 0.0f)
        buildLods(*draw_list, *scene);
    // Layer triangles by (frame, e1 in 1/1000°, eye, kind): LIWC revisits the same candidates.
    std::map<std::tuple<int64_t, int64_t, int, int>, double> drawn_cache;
    const LayerHoles server_holes{.enabled = !o.no_holes};
    auto layer_triangles = [&](int64_t frame, const LayerPlan& plan, int eye, int kind) {
        const auto cache_key = std::make_tuple(
            frame, static_cast<int64_t>(std::llround(plan.e1_deg * 1000.0)), eye, kind);
        if (auto it = drawn_cache.find(cache_key); it != drawn_cache.end())
            return it->second;
        const double content_ms = contentTimeMs(frame, profile->refresh_hz);
        const LayerKind lk = kind == 0   ? LayerKind::kFovea
                             : kind == 1 ? LayerKind::kMiddle
                                         : LayerKind::kOuter;
        const double tris = double(layerTriangles(
            *draw_list, *profile, plan, poseAt(traces.motion, content_ms), static_cast<Eye>(eye),
            lk, o.lod_px, CameraOptions{}, lk == LayerKind::kFovea ? LayerHoles{} : server_holes));
        drawn_cache.emplace(cache_key, tris);
        return tris;
    };
    // The fragments a design's fovea pass shaded at frame k, as its own run's headset counted them
    // (FrameTelemetry::fovea_fragments, both eyes): the overdraw the fovea law charges (docs/
    // MODEL.md §8, "Fragments"). A count of the content at that pose and e1, as the triangles
    // are, not a time. Where the model's e1 differs from the run's (LIWC's choices), the run's
    // fragments per fovea pixel times the model's pixels; none counted: −1, the law's mean.
    const LayerPlanner fragment_planner(*profile);
    auto foveaFragmentsOf = [&](const DesignRun& r) {
        std::vector<std::pair<double, double>> by_frame;  // e1, fragments per eye
        for (const FrameTelemetry& t : r.result.frames) {
            if (t.frame < 0 || t.frame > 1000000)
                continue;
            if (by_frame.size() <= size_t(t.frame))
                by_frame.resize(size_t(t.frame) + 1, {0.0, -1.0});
            by_frame[size_t(t.frame)] = {t.e1_deg,
                                         t.fovea_fragments > 0.0 ? t.fovea_fragments / 2.0 : -1.0};
        }
        return [&, by_frame](int64_t frame, const LayerPlan& plan, int eye) -> double {
            if (frame < 0 || size_t(frame) >= by_frame.size() || by_frame[size_t(frame)].second < 0)
                return -1.0;
            const auto [e1, frags] = by_frame[size_t(frame)];
            const LayerRect& model = plan.eyes[size_t(eye)].fovea;
            if (std::fabs(plan.e1_deg - e1) < 1e-3 || model.empty())
                return frags;
            const double content_ms = contentTimeMs(frame, profile->refresh_hz);
            const LayerPlan run_plan = fragment_planner.plan(gazeAt(traces.gaze, content_ms), e1);
            const double run_px = double(run_plan.eyes[size_t(eye)].fovea.pixels());
            return run_px > 0.0 ? frags * double(model.pixels()) / run_px : -1.0;
        };
    };
    if (rcosts.bits_per_px_at_1 > 0.0) {
        const auto t0 = std::chrono::steady_clock::now();
        WorkloadProbe probe(*profile, bvh);
        if (o.ring_counts == "clusters")
            probe.useClusters(draw_list, o.lod_px);
        probe.setName("qvr-run-prediction", "qvr run: the run's poses and gazes, LIWC's rings");
        WorkloadTrace t;
        t.header = probe.header();
        // An interrupted run predicts the frames its designs got through, not the ones asked for.
        size_t predict_frames = static_cast<size_t>(o.frames);
        if (interrupted) {
            predict_frames = 0;
            for (const DesignRun& r : runs)
                predict_frames = std::max(predict_frames, r.result.frames.size());
        }
        for (size_t i = 0; i < predict_frames; ++i) {
            const double content_ms = contentTimeMs(static_cast<int64_t>(i), profile->refresh_hz);
            WorkloadFrame wf =
                probe.frame(static_cast<int64_t>(i), content_ms, poseAt(traces.motion, content_ms),
                            gazeAt(traces.gaze, content_ms), 180.0);
            for (size_t k = 0; k < wf.bits_per_pixel.size(); ++k)
                wf.bits_per_pixel[k] = rcosts.bits_per_px_at_1 *
                                       std::pow(t.header.scales[k], rcosts.bits_scale_exponent);
            // The calibration coded this very head pose as its frame i: the frame's own bits.
            if (rcosts.bitsFrameMeasured(i, frameContentKey(wf.head)))
                ++bits_frames_own;
            t.frames.push_back(std::move(wf));
        }
        trace = std::move(t);
        trace_source = fmt::format(
            "the run's poses and gazes, {} ring counts computed after the run ({:.1f} s), bits "
            "per pixel from the calibration ({} of {} frames their own, coded by the calibration "
            "on the same head pose; the rest its law); layer triangles drawn (LOD, holes) counted "
            "off the clock; the fovea's shaded fragments as each design's own passes counted them "
            "(a count, not a time: its overdraw, docs/MODEL.md §8 \"Fragments\")",
            o.ring_counts,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
            bits_frames_own, predict_frames);
    } else if (recorded_workload) {
        trace = loadWorkloadTrace(workload_path.string());
        trace_source = "workload.jsonl recorded by the qvr design";
    }
    if (trace) {
        double delay_ms = 0.0;
        auto rt_link_check = makeRuntimeLink(o.net, &delay_ms);
        const std::string net_name = o.net.substr(0, o.net.find(','));
        auto spec = networkSpecByName(net_name);
        if (!spec) {
            sim_note = fmt::format(
                "--net '{}' has no paper-model profile; the paper-hardware column uses wifi",
                net_name);
            spec = networkSpecByName("wifi");
        }
        if (!rt_link_check)
            sim_note += (sim_note.empty() ? "" : "; ") +
                        ("no calibrated prediction: " + rt_link_check.error());
        std::ofstream predicted_csv(out / "predicted_frames.csv");
        predicted_csv << "design,frame,e1_deg,pose_ms,t_local_ms,t_remote_ms,headset_busy_ms,"
                         "decision_ms,remote_done_ms,uca_end_ms,display_ms,mtp_ms,uca_ms,bytes,"
                         "reused,served,server_render_ms,server_encode_ms,key_frames\n";
        if (trace && !trace->frames.empty()) {
            for (const DesignRun& r : runs) {
                const std::string name = r.label();
                Design sd = Design::Qvr;
                double fixed_e1 = 5.0;
                if (!simDesignOf(name, sd, fixed_e1))
                    continue;
                // The costs at this design's speed (the probes around it over the reference).
                const std::optional<std::pair<double, double>> speed = speedFactors(r);
                if (speed)
                    speed_json[name] = {{"headset_factor", speed->first},
                                        {"server_factor", speed->second}};
                for (int pass = 0; rt_link_check && pass < (speed ? 2 : 1); ++pass) {
                    // Pass 1 (with probes): the same model with the costs at the probes' speed,
                    // beside the prediction.
                    auto rt_link = makeRuntimeLink(o.net, &delay_ms);
                    RuntimeSimConfig rc;
                    rc.design = sd;
                    rc.fixed_e1_deg = fixed_e1;
                    rc.costs =
                        pass == 1 ? calibrated.atSpeed(speed->first, speed->second) : calibrated;
                    rc.costs.link_delay_ms += delay_ms;
                    rc.pipeline_depth = o.pipeline_depth;
                    rc.wait_limit_ms = o.remote_timeout_ms;
                    rc.frames = static_cast<int>(trace->frames.size());
                    rc.warmup_frames = o.warmup_frames;  // the same frames left out as measured
                    rc.record_scanout = o.video;  // every design's headset copies its scan-out
                    // The trace's frame k is the run's frame k (same poses).
                    rc.layer_triangles = layer_triangles;
                    rc.fovea_fragments = foveaFragmentsOf(r);
                    const RuntimeRunResult pr = simulateRuntime(*trace, rc, **rt_link);
                    const RuntimeSummary& ps = pr.summary;
                    if (pass == 1) {
                        nlohmann::json& pc = predicted_at_probe_speed[name];
                        pc = predictionJson(ps.fps_mean, ps.mtp_ms_mean, ps.mtp_ms_p99,
                                            ps.bytes_per_frame_mean, ps.e1_deg_mean);
                        pc["headset_busy_ms_mean"] = ps.headset_busy_ms_mean;
                        pc["server_busy_ms_mean"] = ps.server_busy_ms_mean;
                        continue;
                    }
                    // The model's frames beside telemetry.csv's, to chase an error to its stage.
                    for (const RuntimeFrame& f : pr.frames)
                        predicted_csv << fmt::format(
                            "{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},"
                            "{:.3f},{:.3f},{:.0f},{:d},{:d},{:.3f},{:.3f},{:d}\n",
                            name, f.index, f.e1_deg, f.pose_ms, f.t_local_ms, f.t_remote_ms,
                            f.headset_busy_ms, f.decision_ms, f.remote_done_ms, f.uca_end_ms,
                            f.display_ms, f.mtp_ms, f.uca_end_ms - f.uca_start_ms, f.bytes,
                            int(f.reused), int(f.served), f.server_render_ms, f.server_encode_ms,
                            f.key_frames);
                    predicted[name] = predictionJson(ps.fps_mean, ps.mtp_ms_mean, ps.mtp_ms_p99,
                                                     ps.bytes_per_frame_mean, ps.e1_deg_mean);
                    predicted[name]["headset_busy_ms_mean"] = ps.headset_busy_ms_mean;
                    predicted[name]["server_busy_ms_mean"] = ps.server_busy_ms_mean;
                    predicted[name]["t_remote_ms_mean"] = ps.t_remote_ms_mean;
                    predicted[name]["frames_reused"] = ps.frames_reused;
                }
                if (spec) {
                    auto sim_link = makeLink(*spec, o.seed);
                    if (!sim_link)
                        continue;
                    SimConfig cfg;
                    cfg.bench = "qvr-run";
                    cfg.design = sd;
                    cfg.frames = static_cast<int>(trace->frames.size());
                    const RunResult pr = simulate(*trace, cfg, **sim_link);
                    predicted_paper[name] = predictionJson(
                        pr.summary.fps_mean, pr.summary.mtp_ms_mean, pr.summary.mtp_ms_p99,
                        pr.summary.bytes_per_frame_mean, pr.summary.e1_deg_mean);
                    sim_json[name] = predicted_paper[name];
                }
            }
        }
    } else {
        sim_note =
            "no prediction: the workload is recorded during the qvr design's run, and "
            "--designs has no qvr";
    }

    // summary.json
    nlohmann::json j;
    j["command"] = o.command_line;
    j["date"] = experiment::utcNow();
    j["machine"] = experiment::machineDescription();
    j["scene"] = scene->name;
    j["profile"] = {{"name", profile->name},
                    {"width_px", profile->width_px},
                    {"height_px", profile->height_px},
                    {"refresh_hz", profile->refresh_hz}};
    j["net"] = o.net;
    j["frames_per_design"] = o.frames;
    j["interrupted"] = interrupted;
    if (interrupted)
        j["interrupted_note"] = interrupted_note;
    j["designs_requested"] = designs->size();
    j["designs_run"] = runs.size();
    j["pinning"] = {{"client_core", client_core},
                    {"server_core", server_core},
                    {"cores", cores},
                    {"how",
                     "two processes: the server (qvr server --core N) pins its main thread before "
                     "it creates any other, so all its threads (render, llvmpipe, x264, asio) run "
                     "on its core; the headset thread of this process is pinned to the other core "
                     "and its threads (llvmpipe, x264, asio) inherit the mask"}};
    j["run_seconds"] = run_s;
    j["headset_share"] = o.headset_share;
    if (share_group) {
        const CpuShareGroup::Throttling th = share_group->throttling();
        j["headset_throttling"] = {{"periods", th.periods},
                                   {"throttled_periods", th.throttled_periods},
                                   {"throttled_ms", th.throttled_ms},
                                   {"cgroup", share_group->path()}};
    }
    nlohmann::json dj = nlohmann::json::object();
    const DesignSummary* local = nullptr;
    const DesignSummary* remote = nullptr;
    const DesignSummary* qvr = nullptr;
    for (size_t ri = 0; ri < runs.size(); ++ri) {
        const DesignRun& r = runs[ri];
        const std::string name = r.label();
        dj[name] = summaryJson(r.result.summary, r.result.stats);
        // The two sides' own costs, as the model counts them, to tell which side an error is
        // on: the headset's busy time per frame after the start-up (the frames the summary
        // left out, as the model leaves them out), the server's render and
        // encode per served frame (docs/MODEL.md §8, "Stage errors").
        {
            const DesignSummary& s = r.result.summary;
            dj[name]["headset_busy_ms_mean"] = s.headset_busy_frames > 0
                                                   ? nlohmann::json(s.headset_busy_ms_mean)
                                                   : nlohmann::json();
            const bool served = ri < server_busy.size() && server_busy[ri].frames > 0;
            dj[name]["server_busy_ms_mean"] =
                served ? nlohmann::json(server_busy[ri].busy_ms_mean) : nlohmann::json();
        }
        if (predicted.contains(name)) {
            dj[name]["predicted"] = predicted[name];
            dj[name]["prediction_error_pct"] = errorPctJson(predicted[name], dj[name]);
            dj[name]["prediction_error_abs"] = {
                {"e1_deg_mean",
                 predicted[name].value("e1_deg_mean", 0.0) - dj[name].value("e1_deg_mean", 0.0)}};
        }
        if (predicted_paper.contains(name))
            dj[name]["predicted_paper_hardware"] = predicted_paper[name];
        if (predicted_at_probe_speed.contains(name)) {
            dj[name]["predicted_at_probe_speed"] = predicted_at_probe_speed[name];
            dj[name]["prediction_error_pct_at_probe_speed"] =
                errorPctJson(predicted_at_probe_speed[name], dj[name]);
            dj[name]["prediction_error_abs_at_probe_speed"] = {
                {"e1_deg_mean", predicted_at_probe_speed[name].value("e1_deg_mean", 0.0) -
                                    dj[name].value("e1_deg_mean", 0.0)}};
        }
        {
            nlohmann::json sp = {{"before", nullptr}, {"after", nullptr}};
            for (const auto& [when, p] :
                 {std::pair{"before", r.speed_before}, std::pair{"after", r.speed_after}})
                if (p)
                    sp[when] = {{"headset_frame_ms", p->headset_ms},
                                {"server_frame_ms", p->server_ms}};
            if (speed_json.contains(name)) {
                sp["headset_factor"] = speed_json[name]["headset_factor"];
                sp["server_factor"] = speed_json[name]["server_factor"];
            }
            dj[name]["speed"] = sp;
        }
        if (r.design() == Design::Local)
            local = &r.result.summary;
        if (r.design() == Design::Remote)
            remote = &r.result.summary;
        if (r.design() == Design::Qvr)
            qvr = &r.result.summary;
    }
    j["designs"] = dj;
    // The fixed designs run (ffr is fixed:5): the best in hindsight, by displayed FPS.
    const DesignRun* best_fixed = nullptr;
    for (const DesignRun& r : runs)
        if ((r.design() == Design::Fixed || r.design() == Design::Ffr) &&
            (!best_fixed || r.result.summary.fps_mean > best_fixed->result.summary.fps_mean))
            best_fixed = &r;
    if (best_fixed) {
        nlohmann::json bf = {{"design", best_fixed->label()},
                             {"e1_deg", best_fixed->spec.fixed_e1_deg},
                             {"fps_mean", best_fixed->result.summary.fps_mean},
                             {"mtp_ms_p99", best_fixed->result.summary.mtp_ms_p99}};
        for (const DesignRun& r : runs)
            if (r.design() == Design::Qvr || r.design() == Design::Sw)
                bf[std::string(r.label()) + "_fps_over_best_fixed"] =
                    r.result.summary.fps_mean / std::max(1e-9, best_fixed->result.summary.fps_mean);
        j["best_fixed"] = bf;
    }
    nlohmann::json ratios = nlohmann::json::object();
    if (qvr && local && local->fps_mean > 0)
        ratios["qvr_fps_over_local"] = qvr->fps_mean / local->fps_mean;
    if (qvr && remote && remote->bytes_per_frame_mean > 0)
        ratios["qvr_bytes_saved_vs_remote"] =
            1.0 - qvr->bytes_per_frame_mean / remote->bytes_per_frame_mean;
    ratios["paper_qvr_fps_over_local"] = 3.4;
    ratios["paper_qvr_bytes_saved_vs_remote"] = 0.85;
    if (sim_json.contains("qvr") && sim_json.contains("local") &&
        sim_json["local"]["fps_mean"].get<double>() > 0)
        ratios["sim_qvr_fps_over_local"] =
            sim_json["qvr"]["fps_mean"].get<double>() / sim_json["local"]["fps_mean"].get<double>();
    if (sim_json.contains("qvr") && sim_json.contains("remote") &&
        sim_json["remote"]["bytes_per_frame_mean"].get<double>() > 0)
        ratios["sim_qvr_bytes_saved_vs_remote"] =
            1.0 - sim_json["qvr"]["bytes_per_frame_mean"].get<double>() /
                      sim_json["remote"]["bytes_per_frame_mean"].get<double>();
    j["ratios"] = ratios;
    j["sim_prediction"] = sim_json;  // the paper-hardware model, as before
    j["calibration"] = {{"source", calibration->source},      {"path", calibration->path},
                        {"seconds", calibration->seconds},    {"note", calibration->note},
                        {"bits_frames_own", bits_frames_own}, {"workload", trace_source},
                        {"pipeline_depth", o.pipeline_depth}};
    // The speed reference the per-design probes (designs.<d>.speed) are read against.
    j["calibration"]["speed_reference"] = {
        {"headset_frame_ms", calibrated.speed_reference_headset_ms},
        {"server_frame_ms", calibrated.speed_reference_server_ms},
        {"note", speed_note.empty()
                     ? std::string("designs.<d>.speed: the probes around each design, their "
                                   "ratio to this reference, and predicted_at_probe_speed: the "
                                   "model with the design's costs at that ratio")
                     : speed_note},
        {"run_spread_pct", {{"headset", speed_spread_pct[0]}, {"server", speed_spread_pct[1]}}},
        {"run_over_reference", speed_over_reference[0] > 0.0
                                   ? nlohmann::json{{"headset", speed_over_reference[0]},
                                                    {"server", speed_over_reference[1]}}
                                   : nlohmann::json()},
        {"unsteady", unsteady}};
    if (!sim_note.empty())
        j["sim_note"] = sim_note;
    // The server's own counters (all designs together), as its process wrote them on exit.
    j["server"] = server_stats;
    j["server"]["exit_status"] = server_status;
    j["trace"] = trace_json;
    {
        nlohmann::json qj = nlohmann::json::object();
        const char* band_names[5] = {"fovea", "blend", "middle", "outer", "all"};
        for (const auto& [name, q] : quality) {
            nlohmann::json d = {{"frames_sampled", q.frames}, {"seconds", q.seconds}};
            for (size_t i = 0; i < 5; ++i)
                if (q.counted[i] > 0)
                    d[band_names[i]] = {{"psnr_db", q.psnr_db[i]}, {"ssim", q.ssim[i]}};
            nlohmann::json bins = nlohmann::json::array();
            for (const auto& [deg, sn] : q.psnr_by_ecc)
                bins.push_back({deg, sn.first / sn.second});
            d["psnr_db_by_eccentricity_deg"] = bins;
            qj[name] = d;
        }
        if (!quality_note.empty())
            qj["note"] = quality_note;
        j["quality"] = qj;
    }
    const double layers = server_stats.value("layers_rendered", 0.0);
    const double frames_rendered = server_stats.value("frames_rendered", 0.0);
    if (layers > 0)
        j["server"]["encode_ms_per_layer"] = server_stats.value("encode_ms_total", 0.0) / layers;
    if (frames_rendered > 0)
        j["server"]["render_ms_per_frame"] =
            server_stats.value("render_ms_total", 0.0) / frames_rendered;

    // Video of what the headset displayed for qvr.
    std::string video_note = "not recorded";
    if (o.video && recorder.frames() > 0) {
        const fs::path video = out / "qvr_display.mp4";
        if (auto st = recorder.writeMp4(video.string()); st)
            video_note = fmt::format(
                "qvr_display.mp4: {} frames, both eyes side by side at a quarter of "
                "the resolution{}, H.264 in MP4 at {} fps; recording cost the qvr headset "
                "{:.2f} ms a frame, and every other design the same for a stand-in (buffers "
                "reserved before the run, encoded after it)",
                recorder.frames(), o.fovea_border ? ", fovea edge (e1) drawn in yellow" : "",
                profile->refresh_hz, recorder.recordMsPerFrame());
        else
            video_note = "video failed: " + st.error();
        // The middle frame as a still beside it.
        const size_t still = recorder.frames() / 2;
        if (auto st = recorder.writePngFrame(still, (out / "qvr_display_still.png").string()); st)
            video_note += fmt::format("; frame {} of it as qvr_display_still.png", still);
    }
    // The video as a player sees it, read back through libavformat.
    if (fs::exists(out / "qvr_display.mp4")) {
        if (auto info = probeVideoFile((out / "qvr_display.mp4").string()))
            j["video"] = {{"path", "qvr_display.mp4"}, {"container", info->format_name},
                          {"codec", info->codec_name}, {"profile", info->profile},
                          {"width_px", info->width},   {"height_px", info->height},
                          {"fps", info->fps},          {"frames", info->frames}};
        else
            video_note += "; the written MP4 does not read back: " + info.error();
    }
    std::ofstream(out / "summary.json") << j.dump(2) << "\n";

    // Figures.
    report::Plotter plotter(out, 1000, 420);
    const std::string kFpsE1Title =
        "Displayed FPS over the fovea size: the fixed sweep and where qvr (LIWC) and sw run";
    int fixed_points = 0;
    const std::array<std::pair<std::string, std::string>, 4> kFigureTitles = {{
        {"e1", "Fovea size e1 per frame (deg)"},
        {"mtp", "Motion-to-photon latency per frame (ms)"},
        {"bytes", "Bytes received per frame (KB, log scale)"},
        {"scanout", "Interval between scan-outs (ms)"},
    }};
    {
        const std::string common = "set datafile separator ','\nset key outside right\nset grid\n";
        std::string e1_plot = common + "set xlabel 'frame'\nset ylabel 'e1 (deg)'\nplot ";
        std::string mtp_plot =
            common + "set xlabel 'frame'\nset ylabel 'motion-to-photon (ms)'\nplot ";
        std::string bytes_plot =
            common + "set xlabel 'frame'\nset ylabel 'KB per frame'\nset logscale y\nplot ";
        std::string ft_plot = common +
                              "prev=0\nset yrange [0:150]\nset xlabel 'frame'\nset ylabel "
                              "'scan-out interval (ms)'\nplot ";
        bool first = true;
        for (const DesignRun& r : runs) {
            const std::string f = fmt::format("frames_{}.csv", r.label());
            const std::string sep = first ? "" : ", ";
            // Columns (1-based, telemetryCsvHeader): 2 frame, 3 e1, 21 display_ns, 22 bytes, 31
            // mtp.
            e1_plot +=
                fmt::format("{}'{}' every ::1 using 2:3 with lines title '{}'", sep, f, r.label());
            mtp_plot +=
                fmt::format("{}'{}' every ::1 using 2:31 with lines title '{}'", sep, f, r.label());
            bytes_plot +=
                fmt::format("{}'{}' every ::1 using 2:($22/1000+0.001) with lines title '{}'", sep,
                            f, r.label());
            ft_plot += fmt::format(
                "{}'{}' every ::1 using 2:(d=($21-prev)/1e6, prev=$21, d) with lines title '{}'",
                sep, f, r.label());
            first = false;
        }
        plotter.plot("e1", kFigureTitles[0].second, e1_plot + "\n");
        plotter.plot("mtp", kFigureTitles[1].second, mtp_plot + "\n");
        plotter.plot("bytes", kFigureTitles[2].second, bytes_plot + "\n");
        plotter.plot("scanout", kFigureTitles[3].second, ft_plot + "\n");
        // The fixed sweep: displayed FPS over e1, with LIWC's (and sw's) operating point.
        std::ofstream sweep(out / "fps_vs_e1.csv");
        sweep << "design,kind,e1_deg,fps,mtp_ms_p99\n";
        for (const DesignRun& r : runs) {
            const bool fixed = r.design() == Design::Fixed || r.design() == Design::Ffr;
            const bool adaptive = r.design() == Design::Qvr || r.design() == Design::Sw;
            if (!fixed && !adaptive)
                continue;
            fixed_points += fixed ? 1 : 0;
            sweep << fmt::format("{},{},{:.3f},{:.3f},{:.3f}\n", r.label(),
                                 fixed ? "fixed" : r.label(), r.result.summary.e1_deg_mean,
                                 r.result.summary.fps_mean, r.result.summary.mtp_ms_p99);
        }
        sweep.close();
        if (fixed_points >= 2)
            plotter.plot(
                "fps_e1", kFpsE1Title,
                common +
                    "set xlabel 'e1 (deg): fixed designs, and the mean e1 of adaptive ones'\n"
                    "set ylabel 'displayed FPS'\n"
                    "plot 'fps_vs_e1.csv' every ::1 using (strcol(2) eq 'fixed' ? $3 : 1/0):4 "
                    "with linespoints pt 7 title 'fixed e1', "
                    "'' every ::1 using (strcol(2) eq 'qvr' ? $3 : 1/0):4 with points pt 9 ps 2.5 "
                    "title 'qvr (LIWC)', "
                    "'' every ::1 using (strcol(2) eq 'sw' ? $3 : 1/0):4 with points pt 5 ps 2 "
                    "title 'sw'\n");
    }
    if (!quality.empty()) {
        std::string q_plot =
            "set datafile separator ','\nset key outside right\nset grid\nset xlabel "
            "'eccentricity from the gaze (deg)'\nset ylabel 'PSNR (dB)'\nplot ";
        for (size_t i = 0; i < quality.size(); ++i) {
            const std::string f = fmt::format("quality_{}.csv", quality[i].first);
            std::ofstream csv(out / f);
            csv << "eccentricity_deg,psnr_db\n";
            for (const auto& [deg, sn] : quality[i].second.psnr_by_ecc)
                csv << fmt::format("{},{:.3f}\n", deg, sn.first / sn.second);
            q_plot += fmt::format("{}'{}' every ::1 using 1:2 with linespoints title '{}'",
                                  i ? ", " : "", f, quality[i].first);
        }
        plotter.plot("quality", "Display error vs eccentricity: PSNR against a full render (dB)",
                     q_plot + "\n");
    }

    // report.html
    auto num = [](double v, int prec = 1) { return fmt::format("{:.{}f}", v, prec); };
    report::HtmlReport page("qvr run");
    page.heading(1, "qvr run");
    page.html("<p>" + report::htmlEscape(o.command_line) + "<br>" +
              report::htmlEscape(experiment::utcNow()) + ", " +
              report::htmlEscape(experiment::machineDescription()) + "</p>\n");
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
        report::htmlEscape(scene->name), profile->width_px, profile->height_px, profile->refresh_hz,
        report::htmlEscape(o.net), o.frames, o.warmup_frames, client_core, server_core));
    report::Table designs_table({"design", "FPS", "MTP mean ms", "MTP p99 ms", "KB/frame",
                                 "e1 mean °", "T_local ms", "T_remote ms", "UCA ms", "displayed",
                                 "reused", "start-up MTP max ms"});
    for (const DesignRun& r : runs) {
        const DesignSummary& s = r.result.summary;
        designs_table.row({s.design, num(s.fps_mean), num(s.mtp_ms_mean), num(s.mtp_ms_p99),
                           num(s.bytes_per_frame_mean / 1e3), num(s.e1_deg_mean),
                           num(s.t_local_ms_mean), num(s.t_remote_ms_mean), num(s.uca_ms_mean),
                           std::to_string(s.frames_displayed), std::to_string(s.frames_reused),
                           num(s.startup_mtp_ms_max)});
    }
    page.table(designs_table);
    if (j.contains("best_fixed")) {
        const nlohmann::json& bf = j["best_fixed"];
        std::string text = fmt::format(
            "Best fixed fovea in hindsight among those run: {} at {:.1f} FPS (MTP p99 {:.1f} ms).",
            bf["design"].get<std::string>(), bf["fps_mean"].get<double>(),
            bf["mtp_ms_p99"].get<double>());
        for (const char* d : {"qvr", "sw"})
            if (bf.contains(std::string(d) + "_fps_over_best_fixed"))
                text += fmt::format(" {} reaches {:.2f}x its FPS.", d,
                                    bf[std::string(d) + "_fps_over_best_fixed"].get<double>());
        page.paragraph(text);
    }
    limitsHtml(page, runs);
    countersHtml(page, runs, j["server"]);
    page.html(validationHtml(
        dj,
        calibration->note + "; workload: " + trace_source + "; " +
            (speed_note.empty()
                 ? fmt::format("speed probes (a fixed headset and server frame) before and "
                               "after each design moved {:.0f}% (headset) and {:.0f}% (server) "
                               "over the run{}",
                               speed_spread_pct[0], speed_spread_pct[1],
                               unsteady ? ": the machine was unsteady, and a design's FPS moves "
                                          "with it within the seconds it runs, which no probe "
                                          "between designs follows"
                                        : "")
                 : speed_note),
        sim_note));
    page.heading(2, "Against the paper");
    {
        // The headline ratios: measured here, the paper's, the paper-hardware model's.
        auto cell = [&](const char* name, double scale, int prec) -> std::string {
            return ratios.contains(name) ? num(ratios[name].get<double>() * scale, prec) : "—";
        };
        report::Table t({"ratio", "measured", "paper", "simulator (paper hardware)"});
        t.row({"Q-VR FPS over local (x)", cell("qvr_fps_over_local", 1, 2),
               cell("paper_qvr_fps_over_local", 1, 2), cell("sim_qvr_fps_over_local", 1, 2)});
        t.row({"Q-VR bytes saved vs remote (%)", cell("qvr_bytes_saved_vs_remote", 100, 1),
               cell("paper_qvr_bytes_saved_vs_remote", 100, 1),
               cell("sim_qvr_bytes_saved_vs_remote", 100, 1)});
        page.table(t);
    }
    if (plotter.available())
        for (const auto& [name, title] : kFigureTitles)
            page.figure(out, name, title, 1000);
    if (plotter.available() && fixed_points >= 2)
        page.figure(out, "fps_e1", kFpsE1Title, 1000);
    else
        page.paragraph(plotter.note());
    page.heading(2, "Image quality against a full-resolution render");
    if (quality.empty()) {
        page.paragraph(o.quality_every > 0 ? "Not measured: " + quality_note
                                           : "Not measured (--quality-every 0).");
    } else {
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
                         "middle dB", "middle SSIM", "outer dB", "outer SSIM", "all dB",
                         "all SSIM"});
        for (const auto& [name, q] : quality) {
            std::vector<report::Cell> row = {name, std::to_string(q.frames)};
            for (size_t i = 0; i < 5; ++i) {
                row.emplace_back(q.counted[i] ? num(q.psnr_db[i]) : "—");
                row.emplace_back(q.counted[i] ? num(q.ssim[i], 3) : "—");
            }
            t.row(std::move(row));
        }
        page.table(t);
        if (plotter.available())
            page.figure(out, "quality",
                        "Display error vs eccentricity: PSNR against a full render (dB)", 1000);
    }
    page.paragraph("Timeline: " + trace_note +
                   ". Both processes read CLOCK_MONOTONIC of this machine, so the true offset "
                   "is 0; the estimate checks that the stamps agree.");
    page.paragraph("Video: " + video_note);
    if (fs::exists(out / "qvr_display.mp4"))
        page.video("qvr_display.mp4", "qvr_display_still.png", 1000);
    if (fs::exists(out / "qvr_display_still.png"))
        page.image("qvr_display_still.png", "a frame the headset displayed for qvr", 1000);
    if (auto st = page.write(out / "report.html"); !st)
        std::fprintf(stderr, "qvr run: %s\n", st.error().c_str());

    fmt::print("  ratios: {}\n", ratios.dump());
    if (!predicted.empty()) {
        fmt::print(
            "  calibrated prediction ({}): error of FPS, MTP mean, bytes/frame; e1; and of each "
            "side's own cost (headset busy per frame, server render+encode per served frame)\n",
            calibration->source);
        for (auto it = dj.begin(); it != dj.end(); ++it) {
            if (!it.value().contains("prediction_error_pct"))
                continue;
            const nlohmann::json& e = it.value()["prediction_error_pct"];
            const nlohmann::json sp = it.value().value("speed", nlohmann::json::object());
            fmt::print(
                "    {:8} fps {:>8}  mtp {:>8}  bytes {:>8}  e1 {:>7}  | headset {:>7}  server "
                "{:>7}  | speed x{} x{}: fps {:>7}\n",
                it.key(), fmtCell(e["fps_mean"], "{:+.1f}%"), fmtCell(e["mtp_ms_mean"], "{:+.1f}%"),
                fmtCell(e["bytes_per_frame_mean"], "{:+.1f}%"),
                fmtCell(it.value()["prediction_error_abs"]["e1_deg_mean"], "{:+.1f}°"),
                fmtCell(e.value("headset_busy_ms_mean", nlohmann::json()), "{:+.1f}%"),
                fmtCell(e.value("server_busy_ms_mean", nlohmann::json()), "{:+.1f}%"),
                fmtCell(sp.value("headset_factor", nlohmann::json()), "{:.3f}"),
                fmtCell(sp.value("server_factor", nlohmann::json()), "{:.3f}"),
                fmtCell(it.value()
                            .value("prediction_error_pct_at_probe_speed", nlohmann::json::object())
                            .value("fps_mean", nlohmann::json()),
                        "{:+.1f}%"));
        }
        fmt::print("  speed: {}\n",
                   speed_note.empty()
                       ? fmt::format("the probes around each design over the calibration's "
                                     "(headset, server), and the FPS error of the prediction with "
                                     "the design's costs at that speed (summary.json "
                                     "designs.<d>.speed, predicted_at_probe_speed); the probes "
                                     "moved {:.0f}% / {:.0f}% over the run",
                                     speed_spread_pct[0], speed_spread_pct[1])
                       : speed_note);
        if (unsteady)
            fmt::print(
                "  warning: the machine's speed moved by {:.0f}% during the run (the speed probes "
                "between designs, over {:.0f}%): a design's FPS moves with it within the seconds "
                "it runs, which no prediction made around it follows; measure on a steady "
                "machine to judge the model (summary.json calibration.speed_reference)\n",
                std::max(speed_spread_pct[0], speed_spread_pct[1]), kUnsteadySpeedPct);
    }
    if (const double off = std::max(std::fabs(speed_over_reference[0] - 1.0),
                                    std::fabs(speed_over_reference[1] - 1.0));
        speed_over_reference[0] > 0.0 && off > 0.10)
        fmt::print(
            "  warning: this run's speed probes took x{:.2f} (headset) and x{:.2f} (server) the "
            "time the calibration's did: the machine is not as fast as when it was calibrated "
            "({}); `qvr run --recalibrate` measures it again\n",
            speed_over_reference[0], speed_over_reference[1], calibration->path);
    if (!sim_note.empty())
        fmt::print("  {}\n", sim_note);
    fmt::print(
        "  {}\n  {}\n  wrote {}/summary.json, telemetry.csv, frames_*.csv, report.html in {:.0f} "
        "s\n",
        video_note, trace_note, o.out, run_s);
    if (interrupted) {
        std::fprintf(stderr, "qvr run: %s; wrote what was measured to %s\n",
                     interrupted_note.c_str(), o.out.c_str());
        return 130;
    }
    if (!never_shown.empty()) {
        std::fprintf(stderr,
                     "qvr run: %s never showed a layer from the server (summary.json "
                     "startup_unfinished); wrote what was measured to %s\n",
                     fmt::format("{}", fmt::join(never_shown, ", ")).c_str(), o.out.c_str());
        return 1;
    }
    return 0;
}

}  // namespace

static Registered registerRun(CLI::App& app) {
    auto o = std::make_shared<RunOptions>();
    CLI::App* cmd = app.add_subcommand(
        "run", "Server + headset on loopback (each on its own core): every design, measured");
    cmd->add_option("--scene", o->scene, "Scene (builtin:room, openarena:MAP, a file)")
        ->capture_default_str();
    cmd->add_option("--motion", o->motion,
                    "Head motion: default (CMU BVH), a .bvh, a pose CSV, still")
        ->capture_default_str();
    cmd->add_option("--gaze", o->gaze, "Gaze: model (seeded), center, or a gaze CSV")
        ->capture_default_str();
    cmd->add_option("--net", o->net,
                    "Link spec for net's emulator (wifi, lte, 5g, rate:MBPS, trace:...)")
        ->capture_default_str();
    cmd->add_option("--frames", o->frames, "Frames per design")->capture_default_str();
    cmd->add_option("--designs", o->designs,
                    "Comma-separated: local, remote, ffr (= fixed:5), fixed:E for any e1 E in "
                    "degrees, sw, qvr")
        ->capture_default_str();
    cmd->add_option(
           "--profile", o->profile,
           "Display profile: run (480x540), small (320x360), default (1920x2160), low, TOML")
        ->capture_default_str();
    cmd->add_option("--out", o->out, "Output folder")->capture_default_str();
    cmd->add_option("--codec", o->codec, "Codec backend: x264 or raw")->capture_default_str();
    cmd->add_option("--seed", o->seed, "Gaze model and simulator seed")->capture_default_str();
    cmd->add_option("--remote-timeout-ms", o->remote_timeout_ms,
                    "Remote layers later than this after the local render are late (frame reuse)")
        ->check(CLI::Range(1.0, 10000.0))
        ->capture_default_str();
    cmd->add_flag("--one-pass-periphery", o->one_pass_periphery,
                  "Server renders middle and outer in one geometry pass per eye (pays when "
                  "vertex-bound: no LOD, small displays)");
    cmd->add_flag("--no-holes", o->no_holes,
                  "Server draws every periphery layer whole, also where the headset's fovea (or "
                  "the middle layer) covers it");
    cmd->add_option("--headset-share", o->headset_share,
                    "Fraction of its core the headset process may use (CFS quota per 10 ms, "
                    "cgroups; needs root): the analogue of Table 4's slower headset GPUs")
        ->check(CLI::Range(CpuShareGroup::kMinShare + 1e-9, 1.0))
        ->capture_default_str();
    cmd->add_option("--ring-counts", o->ring_counts,
                    "LIWC's triangle rings: clusters (what the fovea draws, cheap) or bvh "
                    "(every scene triangle, exact, the earlier input)")
        ->check(CLI::IsMember({"clusters", "bvh"}))
        ->capture_default_str();
    addLodOption(cmd, o->lod_px);
    cmd->add_option("--warmup-frames", o->warmup_frames,
                    "Each design's first frames are its session's start-up (connection, first "
                    "renders, key frames, the policy's first decisions; for a design that asks the "
                    "server for layers, also until the first of them is on screen): run and "
                    "logged, but left out of FPS, MTP, bytes and e1; their worst MTP is reported "
                    "apart")
        ->capture_default_str();
    cmd->add_option("--pipeline", o->pipeline_depth,
                    "Frames in flight on the headset: 1 (sequential) or 2 (request n+1 before "
                    "finishing n)")
        ->check(CLI::Range(1, 2))
        ->capture_default_str();
    cmd->add_option("--hardware", o->hardware,
                    "Calibration for the prediction (qvr calibrate --out FILE); without it the "
                    "cached calibration of this machine, or a fresh one measured first");
    cmd->add_flag("--recalibrate", o->recalibrate,
                  "Measure the calibration again even when a cached one exists");
    cmd->add_flag("!--no-video", o->video, "Do not record the qvr display video");
    cmd->add_flag("--quiet", o->quiet, "No progress line on a terminal");
    cmd->add_option("--quality-every", o->quality_every,
                    "Measure every Nth displayed frame against a full-resolution render after "
                    "each design's run (0: off)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    cmd->add_flag("!--no-fovea-border", o->fovea_border,
                  "Do not draw the e1 circle (the fovea layer's edge) in the video");
    return {
        cmd, [o] {
            o->command_line = fmt::format(
                "qvr run --scene {} --motion {} --gaze {} --net {} --frames {} --designs {} "
                "--profile {} --codec {} --seed {} --lod-px {} --pipeline {} --headset-share {} "
                "--ring-counts {}{}{}",
                o->scene, o->motion, o->gaze, o->net, o->frames, o->designs, o->profile, o->codec,
                o->seed, o->lod_px, o->pipeline_depth, o->headset_share, o->ring_counts,
                o->one_pass_periphery ? " --one-pass-periphery" : "",
                o->no_holes ? " --no-holes" : "");
            return runRun(*o);
        }};
}

QVR_REGISTER_COMMAND(90, registerRun);

}  // namespace qvr::cli
