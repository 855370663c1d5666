#include "qvr/experiment/design_runs.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "headset_child.h"
#include "qvr/compose/quality.h"
#include "qvr/compose/test_pattern.h"
#include "qvr/render/camera.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/render_server.h"
#include "qvr/runtime/server_process.h"
#include "qvr/runtime/telemetry.h"
#include "qvr/workload/trace_io.h"

namespace qvr::experiment {

namespace fs = std::filesystem;
using namespace qvr::runtime;

std::optional<std::string> reusedPeripheryWarning(const runtime::DesignSummary& s) {
    if (s.frames <= 0 || 2 * s.frames_reused <= s.frames)
        return std::nullopt;
    const double own = ownLayersFps(s.fps_mean, s.frames, s.frames_reused);
    return fmt::format(
        "warning: {}: {} of {} frames re-warped an older periphery (their own layers came after "
        "the wait limit); its {:.1f} FPS counts them, {:.1f} FPS had their own (summary.json "
        "frames_reused)",
        s.design, s.frames_reused, s.frames, s.fps_mean, own);
}

bool showedNoNewLayers(const runtime::DesignSummary& s) {
    return !s.startup_unfinished && s.frames_remote_requested > 0 && s.frames_new_layers == 0;
}

namespace {

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

// Keeps every Nth displayed frame's left eye at full resolution (QualitySample).
class QualitySampler final : public DisplaySink {
public:
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
    const std::vector<QualitySample>& samples() const { return m_samples; }
    // Gives the images back to the pool for the next design.
    void recycle() {
        for (QualitySample& s : m_samples)
            m_pool.push_back(std::move(s.left));
        m_samples.clear();
    }

private:
    int m_every;
    size_t m_max;
    DisplaySink* m_inner;
    std::vector<ImageRgba8>& m_pool;
    std::vector<QualitySample> m_samples;
};

// At most this many quality samples per design.
constexpr size_t kQualitySamples = 12;

// Set by SIGINT/SIGTERM once the designs start: the current design ends at its next frame
// boundary, no further design starts, the server child is stopped (SIGTERM, so it writes its
// stats), and everything measured so far is written; the exit status is then 130.
std::atomic<bool> g_run_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

void onRunSignal(int) {
    g_run_stop.store(true);
}

// The server: `qvr server` in a child process (server_process.h says why), pinned to
// `server_core`. Its key goes through a file only it and we can read, removed once it is
// listening.
std::variant<ServerProcess, RunError> startServer(const RunOptions& plan,
                                                  const net::PresharedKey& key, int server_core) {
    auto exe = selfExecutable();
    if (!exe)
        return RunError{exe.error()};
    char key_path[] = "/tmp/qvr-run-key-XXXXXX";
    const int key_fd = mkstemp(key_path);
    if (key_fd < 0)
        return RunError{"cannot create a key file in /tmp"};
    const std::string key_hex = key.toHex() + "\n";
    const bool key_written =
        write(key_fd, key_hex.data(), key_hex.size()) == static_cast<ssize_t>(key_hex.size());
    close(key_fd);
    const fs::path out(plan.out);
    std::vector<std::string> args = {"server",
                                     "--bind",
                                     "127.0.0.1",
                                     "--port",
                                     "0",
                                     "--key-file",
                                     key_path,
                                     "--scene",
                                     plan.scene,
                                     "--profile",
                                     plan.profile,
                                     "--net",
                                     plan.net,
                                     "--codec",
                                     plan.codec,
                                     "--core",
                                     std::to_string(server_core),
                                     "--stats-json",
                                     (out / "server_stats.json").string(),
                                     "--stamps-csv",
                                     (out / "server_stamps.csv").string(),
                                     "--frames-csv",
                                     (out / "server_frames.csv").string(),
                                     "--lod-px",
                                     fmt::format("{}", plan.lod_px)};
    if (plan.one_pass_periphery)
        args.push_back("--one-pass-periphery");
    if (plan.no_holes)
        args.push_back("--no-holes");
    if (plan.share_periphery != "off")
        args.insert(args.end(), {"--share-periphery", plan.share_periphery});
    auto server = key_written ? ServerProcess::start(*exe, args)
                              : Expected<ServerProcess>(makeError("cannot write the key file"));
    unlink(key_path);
    if (!server)
        return RunError{server.error()};
    return std::move(*server);
}

// The speed probe the run takes before each design and after the last, or why there is none.
std::unique_ptr<SpeedProbe> makeSpeedProbe(const RunOptions& plan, const RuntimeCosts& calibrated,
                                           std::string& note) {
    if (calibrated.speed_reference_headset_ms <= 0.0 || calibrated.speed_reference_server_ms <= 0.0)
        note = "the calibration has no speed reference (calibration version < 14): no speed probes";
    else if (calibrated.speed_reference_key != calibrationCacheKey(runCalibrateOptions(plan)))
        note =
            "the calibration's speed reference was taken on another machine, scene, profile, "
            "codec or level of detail than this run's: no speed probes";
    else if (auto made = SpeedProbe::make(runCalibrateOptions(plan)); !made)
        note = "no speed probes: " + made.error();
    else
        return std::move(*made);
    return nullptr;
}

// Runs the designs one after the other against one server, into a RunMeasurement.
class DesignRunner {
public:
    DesignRunner(const RunOptions& plan, const HmdProfile& profile, const HeadsetInputs& inputs,
                 RunMeasurement& m)
        : m_plan(plan),
          m_profile(profile),
          m_inputs(inputs),
          m_m(m),
          m_out(plan.out),
          m_stand_in(profile, plan.video_max_frames, false, /*keep=*/false) {}

    std::optional<RunError> run(const std::vector<DesignSpec>& designs,
                                const RuntimeCosts& calibrated);

private:
    std::optional<RunError> start(const RuntimeCosts& calibrated);
    void printSetup() const;
    std::optional<SpeedSample> probeSpeedNow();
    HeadsetConfig headsetConfig(const DesignSpec& spec) const;
    // Runs one design; false when the run stops after it (interrupted).
    Expected<bool> runDesign(const DesignSpec& spec, size_t designs_requested);
    void keepRun(const DesignSpec& spec, HeadsetResult result,
                 std::optional<SpeedSample> speed_before);
    void measureQuality(const std::string& label, const QualitySampler& sampler);
    std::optional<RunError> startOtherHeadsets();
    void keepHeadsets(const std::string& label, const DesignSummary* own, int64_t start_ns,
                      bool stopped);
    void finish(size_t designs_requested, const RuntimeCosts& calibrated);
    void writeTrace();

    const RunOptions& m_plan;
    const HmdProfile& m_profile;
    const HeadsetInputs& m_inputs;
    RunMeasurement& m_m;
    const fs::path m_out;
    net::PresharedKey m_key = net::PresharedKey::random();
    std::optional<ServerProcess> m_server;
    std::optional<ScopedThreadPin> m_main_pin;
    std::unique_ptr<SpeedProbe> m_speed_probe;
    std::vector<HeadsetWorkload> m_workloads;  // by headset; [0] is this process's
    std::unique_ptr<OtherHeadsets> m_others;   // headsets 1…N−1 (none when N is 1)
    // Each design's headsets and the span of time they ran in, for the server's share.
    struct HeadsetsWindow {
        std::string design;
        std::vector<HeadsetOutcome> headsets;
        int64_t start_ns = 0, end_ns = 0;
    };
    std::vector<HeadsetsWindow> m_windows;
    ScanoutRecorder m_stand_in;
    std::vector<ImageRgba8> m_quality_pool;  // allocated (and touched) once, before any run
    std::unique_ptr<Renderer> m_quality_renderer;
    std::ofstream m_all_csv;
};

std::optional<RunError> DesignRunner::start(const RuntimeCosts& calibrated) {
    // Two cores: the headset on the first core this process may use, the server's render thread
    // on the last one (the mask, not 0…N−1: under taskset or a cpuset those cores differ).
    const std::vector<int> cores = allowedCores();
    m_m.cores = static_cast<int>(cores.size());
    m_m.client_core = cores.front();
    m_m.server_core = cores.size() > 1 ? cores.back() : -1;
    auto server = startServer(m_plan, m_key, m_m.server_core);
    if (auto* error = std::get_if<RunError>(&server))
        return *error;
    m_server.emplace(std::move(std::get<ServerProcess>(server)));
    // The machine's speed before each design and after the last, on the headset's core while
    // the server waits between sessions: the run reports how far the probes moved, warns when
    // they moved much, and predicts each design a second time with its costs at the ratio of the
    // probes around it to the calibration's reference (docs/MODEL.md §11 says why it is not the
    // prediction). Its process is made before this one joins the headset's CPU share group, so
    // it measures the machine, not the quota (the model applies the share).
    m_speed_probe = makeSpeedProbe(m_plan, calibrated, m_m.speed_note);
    // The headset's share of its core (CFS quota on this process; the server child was made
    // before, so it keeps its whole core).
    if (m_plan.headset_share < 1.0) {
        auto g = CpuShareGroup::create(m_plan.headset_share);
        Status moved = g ? g->addProcess(getpid()) : Status(makeError(g.error()));
        if (!moved) {
            m_server->stop();
            return RunError{fmt::format("--headset-share {:g} refused: {}", m_plan.headset_share,
                                        moved.error()),
                            2};
        }
        m_m.share_group = std::move(*g);
    }
    if (auto error = startOtherHeadsets()) {
        m_server->stop();
        return error;
    }
    printSetup();
    // This thread, and every thread made while the designs run, on the headset's core: the
    // quality pass's renderer is made here, and once the first design's GL display is gone its
    // context makes llvmpipe's rasterizer threads, which the next designs' headsets then share.
    // Made on an unpinned thread they would run on the server's core as well (docs/RUNTIME.md).
    if (m_m.client_core >= 0 && m_m.server_core >= 0) {
        m_main_pin.emplace(m_m.client_core);
        if (!m_main_pin->error().empty())
            std::fprintf(stderr, "qvr run: %s (the main thread runs unpinned)\n",
                         m_main_pin->error().c_str());
    }
    m_m.recorder =
        std::make_unique<ScanoutRecorder>(m_profile, m_plan.video_max_frames, m_plan.fovea_border);
    if (m_plan.quality_every > 0)
        for (size_t k = 0; k < kQualitySamples; ++k)
            m_quality_pool.emplace_back(m_profile.width_px, m_profile.height_px);
    m_all_csv.open(m_out / "telemetry.csv");
    m_all_csv << telemetryCsvHeader();
    return std::nullopt;
}

void DesignRunner::printSetup() const {
    const Scene& scene = *m_inputs.scene;
    fmt::print(
        "qvr run: {} ({} triangles), {}x{} per eye at {} Hz, net {}, {} frames per design (the "
        "first {} start-up, outside the statistics)\n",
        scene.name, scene.triangleCount(), m_profile.width_px, m_profile.height_px,
        m_profile.refresh_hz, m_plan.net, m_plan.frames, m_plan.warmup_frames);
    const auto& share = m_m.share_group;
    fmt::print(
        "  server on 127.0.0.1:{} pinned to core {}, headset pinned to core {} ({} cores){}\n",
        m_server->port(), m_m.server_core, m_m.client_core, m_m.cores,
        share
            ? fmt::format(", headset limited to {:.0f}% of its core (CFS quota "
                          "{:.1f} ms per 10 ms, {})",
                          100.0 * m_plan.headset_share, 10.0 * m_plan.headset_share, share->path())
            : std::string());
}

int64_t steadyNowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// The headsets' workloads, and headsets 1…N−1 ready to start (each its own CPU share group).
std::optional<RunError> DesignRunner::startOtherHeadsets() {
    std::vector<std::string> recordings;
    for (const std::string& r : defaultMotionRecordings())
        if (fs::exists(r))
            recordings.push_back(r);
    m_workloads =
        headsetWorkloads(m_plan.headsets, m_plan.motion, m_plan.gaze, m_plan.seed,
                         m_plan.identical_workloads, recordings, m_plan.headset_offset_ms);
    if (m_plan.headsets <= 1)
        return std::nullopt;
    auto others = OtherHeadsets::make(m_plan, m_workloads, m_m.client_core);
    if (!others)
        return RunError{
            fmt::format("--headset-share {:g} refused: {}", m_plan.headset_share, others.error()),
            2};
    m_others = std::move(*others);
    return std::nullopt;
}

// The design's headsets once headset 0 (`own`, none when it failed) has ended: its outcome, the
// others' (awaited) and the span they ran in.
void DesignRunner::keepHeadsets(const std::string& label, const DesignSummary* own,
                                int64_t start_ns, bool stopped) {
    HeadsetsWindow w{label, {}, start_ns, 0};
    HeadsetOutcome first;
    first.workload = m_workloads.front();
    if (own)
        first.summary = *own;
    else
        first.error = "its session failed";
    w.headsets.push_back(std::move(first));
    if (m_others)
        for (HeadsetOutcome& h : m_others->collect(stopped || !own))
            w.headsets.push_back(std::move(h));
    w.end_ns = steadyNowNs();
    m_windows.push_back(std::move(w));
}

// Headsets 1…N−1's lines below headset 0's, and the design's fairness.
void printHeadsets(const std::vector<HeadsetOutcome>& headsets, const std::string& label) {
    for (const HeadsetOutcome& h : headsets) {
        const DesignSummary& s = h.summary;
        if (h.index == 0)
            continue;
        if (h.error.empty())
            fmt::print(
                "    headset {:2} fps {:6.1f}  mtp {:6.1f} ms (p99 {:6.1f})  {:8.0f} B/frame  e1 "
                "{:5.1f} deg  ({}, seed {}{})\n",
                h.index, s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean,
                s.e1_deg_mean, fs::path(h.workload.motion).stem().string(), h.workload.seed,
                h.workload.ahead_ms > 0.0 ? fmt::format(", {:g} ms ahead", h.workload.ahead_ms)
                                          : std::string());
        else
            fmt::print("    headset {:2} failed: {}\n", h.index, h.error);
    }
    const HeadsetsResult r = aggregateHeadsets(label, headsets, std::nullopt);
    fmt::print("    {} headsets: FPS mean {:.1f}, min {:.1f}, Jain's index {:.3f}\n",
               headsets.size(), r.fps_mean, r.fps_min, r.jain_fairness_fps);
    std::fflush(stdout);
}

std::optional<SpeedSample> DesignRunner::probeSpeedNow() {
    if (!m_speed_probe)
        return std::nullopt;
    auto sample = m_speed_probe->measure();
    if (sample)
        return *sample;
    m_m.speed_note = "the speed probe failed: " + sample.error();
    m_speed_probe.reset();
    return std::nullopt;
}

HeadsetConfig DesignRunner::headsetConfig(const DesignSpec& spec) const {
    HeadsetConfig hc;
    hc.design = spec.design;
    hc.fixed_e1_deg = spec.fixed_e1_deg;
    hc.profile = m_profile;
    hc.codec.backend = m_plan.codec;
    hc.port = m_server->port();
    hc.key = m_key;
    hc.frames = m_plan.frames;
    hc.core = m_m.client_core;
    hc.remote_timeout_ms = m_plan.remote_timeout_ms;
    hc.pipeline_depth = m_plan.pipeline_depth;
    hc.warmup_frames = m_plan.warmup_frames;
    hc.lod_error_px = m_plan.lod_px;
    hc.cluster_ring_counts = m_plan.ring_counts == "clusters";
    hc.stop = &g_run_stop;
    GlRendererOptions gl;
    gl.lod_error_px = m_plan.lod_px;
    hc.renderer = glRendererFactory(gl);
    return hc;
}

Expected<bool> DesignRunner::runDesign(const DesignSpec& spec, size_t designs_requested) {
    const std::string label = spec.label();
    HeadsetConfig hc = headsetConfig(spec);
    std::ofstream workload_out;
    std::unique_ptr<WorkloadTraceWriter> writer;
    if (spec.design == Design::Qvr) {
        if (m_plan.video) {
            m_m.recorder->reserve(m_plan.frames);
            hc.display = m_m.recorder.get();
        }
        // The qvr design probes its ring counts anyway; they are written after its frames
        // (HeadsetConfig::workload), and no other design pays the probe.
        workload_out.open(m_out / "workload.jsonl");
        if (workload_out) {
            writer = std::make_unique<WorkloadTraceWriter>(workload_out);
            hc.workload = writer.get();
            m_m.recorded_workload = true;
        }
    } else if (m_plan.video) {
        m_stand_in.reserve(1);
        hc.display = &m_stand_in;
    }
    std::unique_ptr<QualitySampler> sampler;
    if (m_plan.quality_every > 0) {
        sampler = std::make_unique<QualitySampler>(m_plan.quality_every, kQualitySamples,
                                                   hc.display, m_quality_pool);
        hc.display = sampler.get();
    }
    std::unique_ptr<ProgressDisplay> progress;
    if (!m_plan.quiet && isatty(STDERR_FILENO)) {
        progress = std::make_unique<ProgressDisplay>(label, m_plan.frames, hc.display);
        hc.display = progress.get();
    }
    const std::optional<SpeedSample> speed_before = probeSpeedNow();
    if (!m_m.runs.empty())
        m_m.runs.back().speed_after = speed_before;  // the last design's "after"
    if (m_others)
        if (auto st = m_others->start(label, m_server->port(), m_key.toHex()); !st)
            return makeError(label + ": " + st.error());
    // Every headset's first frame together: the others wait for headset 0's.
    int64_t start_ns = 0;
    hc.before_frame = [&](int64_t frame) {
        if (frame != 0)
            return;
        if (m_others)
            m_others->release();
        start_ns = steadyNowNs();
    };
    Expected<HeadsetResult> result = makeError("not run");
    std::thread headset(
        [&] { result = runHeadset(hc, m_inputs.scene, m_inputs.bvh, m_inputs.traces); });
    headset.join();
    progress.reset();  // clears the progress line
    const bool stopped = g_run_stop.load();
    keepHeadsets(label, result ? &result->summary : nullptr, start_ns, stopped);
    if (!result)
        return makeError(label + ": " + result.error());
    if (stopped) {
        m_m.interrupted_note =
            fmt::format("interrupted during {} after {} of {} frames; {} of {} designs run", label,
                        result->frames.size(), m_plan.frames,
                        m_m.runs.size() + (result->frames.empty() ? 0 : 1), designs_requested);
        if (result->frames.empty())
            return false;  // nothing measured for this design
    }
    keepRun(spec, std::move(*result), speed_before);
    if (m_others)
        printHeadsets(m_windows.back().headsets, label);
    if (stopped) {
        // No quality pass: the user asked to stop.
        if (m_m.quality.empty() && m_m.quality_note.empty())
            m_m.quality_note = "the run was interrupted before the quality pass";
        return false;
    }
    if (sampler && !sampler->samples().empty())
        measureQuality(label, *sampler);
    if (sampler)
        sampler->recycle();
    return true;
}

// Prints the design's line, writes its telemetry and keeps its run.
void DesignRunner::keepRun(const DesignSpec& spec, HeadsetResult result,
                           std::optional<SpeedSample> speed_before) {
    const std::string label = spec.label();
    const DesignSummary& s = result.summary;
    fmt::print(
        "  {:6} fps {:6.1f}  mtp {:6.1f} ms (p99 {:6.1f})  {:8.0f} B/frame  e1 {:5.1f} deg  "
        "displayed {} reused {}\n",
        s.design, s.fps_mean, s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean, s.e1_deg_mean,
        s.frames_displayed, s.frames_reused);
    if (const auto warning = reusedPeripheryWarning(s))
        fmt::print("  {}\n", *warning);
    // A display the server's layers did not keep new: listed (qvr run exits 1) and said.
    const auto stale = [&](std::vector<std::string>& list, const char* key,
                           const std::string& why) {
        list.push_back(label);
        fmt::print("  warning: {}: {} (summary.json {})\n", s.design, why, key);
    };
    if (showedNoNewLayers(s))
        stale(m_m.stale_only, "frames_new_layers",
              fmt::format("none of its {} counted frames showed server layers newer than its "
                          "start-up's: it re-warped the same old periphery throughout",
                          s.frames));
    if (s.startup_unfinished && m_plan.warmup_frames > 0)
        stale(m_m.never_shown, "startup_unfinished",
              fmt::format("the start-up never ended (none of the server's layers reached the "
                          "screen in {} frames); its statistics are over every frame, not a "
                          "steady state",
                          s.frames));
    std::fflush(stdout);
    for (const FrameTelemetry& t : result.frames)
        m_all_csv << telemetryCsvRow(label, t);
    if (auto st = writeTelemetryCsv((m_out / fmt::format("frames_{}.csv", label)).string(), label,
                                    result.frames);
        !st)
        std::fprintf(stderr, "qvr run: %s\n", st.error().c_str());
    m_m.runs.push_back({spec, std::move(result), speed_before, std::nullopt});
}

// Image quality, between the measured runs: each sampled display against a full-resolution
// render of the same frame (rendered now, on this thread).
void DesignRunner::measureQuality(const std::string& label, const QualitySampler& sampler) {
    if (!m_quality_renderer) {
        GlRendererOptions gl;
        gl.lod_error_px = m_plan.lod_px;
        auto made = glRendererFactory(gl)();
        if (made && (*made)->upload(*m_inputs.scene))
            m_quality_renderer = std::move(*made);
        else
            m_m.quality_note = "no reference renderer: " +
                               (made ? std::string("scene upload failed") : made.error());
    }
    if (!m_quality_renderer)
        return;
    auto q =
        measureDesignQuality(sampler.samples(), m_profile, m_inputs.traces, *m_quality_renderer);
    if (q)
        m_m.quality.emplace_back(label, std::move(*q));
    else
        m_m.quality_note = q.error();
}

std::optional<RunError> DesignRunner::run(const std::vector<DesignSpec>& designs,
                                          const RuntimeCosts& calibrated) {
    if (auto error = start(calibrated))
        return error;
    g_run_stop.store(false);
    std::signal(SIGINT, onRunSignal);
    std::signal(SIGTERM, onRunSignal);
    for (const DesignSpec& spec : designs) {
        if (g_run_stop.load())
            break;
        auto go_on = runDesign(spec, designs.size());
        if (!go_on)
            return RunError{go_on.error()};
        if (!*go_on)
            break;
        // Let the server finish the last session before the next one starts.
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    if (!g_run_stop.load() && !m_m.runs.empty())
        m_m.runs.back().speed_after = probeSpeedNow();
    finish(designs.size(), calibrated);
    return std::nullopt;
}

// Ends the run: the speed over it, the server stopped and its counters read, trace.json.
void DesignRunner::finish(size_t designs_requested, const RuntimeCosts& calibrated) {
    m_m.speed = runSpeed(m_m.runs, calibrated);
    // A second Ctrl-C while the report is written ends the process at once.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    m_m.interrupted = g_run_stop.load();
    if (m_m.interrupted && m_m.interrupted_note.empty())
        m_m.interrupted_note = fmt::format("interrupted between designs; {} of {} designs run",
                                           m_m.runs.size(), designs_requested);
    m_all_csv.flush();
    m_main_pin.reset();  // the report's work may use every core
    m_m.server_status = m_server->stop();
    if (std::ifstream f(m_out / "server_stats.json"); f) {
        m_m.server_stats = nlohmann::json::parse(f, nullptr, false);
        if (m_m.server_stats.is_discarded())
            m_m.server_stats = nlohmann::json::object();
    }
    if (m_m.server_status != 0)
        std::fprintf(stderr, "qvr run: the server exited with status %d\n", m_m.server_status);
    writeTrace();
}

// trace.json: every design's headset stages and the server's, on the headset's clock.
void DesignRunner::writeTrace() {
    std::vector<ServerFrameStamps> stamps;
    auto read = readServerStamps((m_out / "server_stamps.csv").string());
    if (read)
        stamps = std::move(*read);
    else
        m_m.trace_note = "no server stages: " + read.error();
    for (HeadsetsWindow& w : m_windows)
        m_m.headsets.push_back(aggregateHeadsets(
            w.design, std::move(w.headsets),
            read ? std::optional(serverShare(stamps, w.start_ns, w.end_ns)) : std::nullopt));
    std::vector<TraceDesign> tds;
    for (const DesignRun& r : m_m.runs)
        tds.push_back({r.label(), r.result.origin_ns, m_profile.refresh_hz, &r.result.frames});
    m_m.server_busy = serverBusyPerDesign(tds, stamps);
    auto info = writeChromeTrace((m_out / "trace.json").string(), tds, stamps);
    if (!info) {
        m_m.trace_note = "trace.json failed: " + info.error();
        std::fprintf(stderr, "qvr run: %s\n", m_m.trace_note.c_str());
        return;
    }
    m_m.trace = *info;
    m_m.trace_note = fmt::format(
        "trace.json ({} events; ui.perfetto.dev or chrome://tracing): server stamps put on the "
        "headset clock with offset {:+.3f} ms ± {:.3f} ms estimated from {} requests{}",
        info->events, info->offset.offset_ns * 1e-6, info->offset.bound_ns * 1e-6,
        info->offset.requests, m_m.trace_note.empty() ? "" : "; " + m_m.trace_note);
}

}  // namespace

Expected<DesignQuality> measureDesignQuality(const std::vector<QualitySample>& samples,
                                             const HmdProfile& profile, const HeadsetTraces& traces,
                                             Renderer& renderer) {
    DesignQuality q;
    const auto t0 = std::chrono::steady_clock::now();
    ImageRgba8 full;
    for (const QualitySample& s : samples) {
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

RunSpeed runSpeed(const std::vector<DesignRun>& runs, const RuntimeCosts& calibrated) {
    std::vector<SpeedSample> all;
    for (const DesignRun& r : runs)
        if (r.speed_before)
            all.push_back(*r.speed_before);
    if (!runs.empty() && runs.back().speed_after)
        all.push_back(*runs.back().speed_after);
    RunSpeed speed;
    if (!all.empty() && calibrated.speed_reference_headset_ms > 0.0 &&
        calibrated.speed_reference_server_ms > 0.0) {
        for (const SpeedSample& p : all) {
            speed.over_reference[0] += p.headset_ms / double(all.size());
            speed.over_reference[1] += p.server_ms / double(all.size());
        }
        speed.over_reference[0] /= calibrated.speed_reference_headset_ms;
        speed.over_reference[1] /= calibrated.speed_reference_server_ms;
    }
    speed.spread_pct = speedProbesSpreadPct(all);
    speed.unsteady = std::max(speed.spread_pct[0], speed.spread_pct[1]) > kUnsteadySpeedPct;
    return speed;
}

std::variant<RunMeasurement, RunError> measureDesigns(const RunOptions& plan,
                                                      const std::vector<DesignSpec>& designs,
                                                      const HmdProfile& profile,
                                                      const HeadsetInputs& inputs,
                                                      const RuntimeCosts& calibrated) {
    RunMeasurement m;
    DesignRunner runner(plan, profile, inputs, m);
    if (auto error = runner.run(designs, calibrated))
        return *error;
    return m;
}

DisplayVideo writeDisplayVideo(const RunOptions& plan, const HmdProfile& profile,
                               const RunMeasurement& measurement) {
    DisplayVideo video;
    const fs::path out(plan.out);
    const ScanoutRecorder* recorder = measurement.recorder.get();
    if (plan.video && recorder && recorder->frames() > 0) {
        if (auto st = recorder->writeMp4((out / "qvr_display.mp4").string()); st)
            video.note = fmt::format(
                "qvr_display.mp4: {} frames, both eyes side by side at a quarter of "
                "the resolution{}, H.264 in MP4 at {} fps; recording cost the qvr headset "
                "{:.2f} ms a frame, and every other design the same for a stand-in (buffers "
                "reserved before the run, encoded after it)",
                recorder->frames(), plan.fovea_border ? ", fovea edge (e1) drawn in yellow" : "",
                profile.refresh_hz, recorder->recordMsPerFrame());
        else
            video.note = "video failed: " + st.error();
        // The middle frame as a still beside it.
        const size_t still = recorder->frames() / 2;
        if (auto st = recorder->writePngFrame(still, (out / "qvr_display_still.png").string()); st)
            video.note += fmt::format("; frame {} of it as qvr_display_still.png", still);
    }
    // The video as a player sees it, read back through libavformat.
    if (fs::exists(out / "qvr_display.mp4")) {
        if (auto info = probeVideoFile((out / "qvr_display.mp4").string()))
            video.info = *info;
        else
            video.note += "; the written MP4 does not read back: " + info.error();
    }
    return video;
}

}  // namespace qvr::experiment
