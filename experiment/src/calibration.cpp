// Micro-benchmarks of the runtime's parts (calibration.h), each alone on one pinned core: the
// headset's fovea (and full-frame) render against pixels and the BVH's triangle count, the
// decision's ring counts, the server's layer render and encode, a stream's decode, UCA per
// frame, the plan; fitted by least squares to RuntimeCosts.
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/scanout_recorder.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "qvr/codec/video_codec.h"
#include "qvr/compose/uca.h"
#include "qvr/experiment/host.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/net/link_emulator.h"
#include "qvr/net/protocol.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/affinity.h"
#include "qvr/runtime/headset_client.h"
#include "qvr/runtime/session.h"
#include "qvr/runtime/workload_probe.h"
#include "qvr/sim/cost_fit.h"
#include "qvr/sim/runtime_model.h"

namespace qvr::experiment {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

using Sample = CostSample;

// A pass's shaded fragments for its cost sample; −1 (not counted) where the driver has no
// pipeline statistics.
double fragmentsOf(const RenderStats& st) {
    return st.fragment_invocations > 0 ? double(st.fragment_invocations) : -1.0;
}

CalibratedPart summarise(const std::string& name, const std::string& what,
                         const std::vector<Sample>& s, const PartCost& cost) {
    CalibratedPart p;
    p.name = name;
    p.what = what;
    p.samples = static_cast<int>(s.size());
    p.cost = cost;
    if (s.empty())
        return p;
    std::vector<double> ms;
    for (const Sample& x : s)
        ms.push_back(x.ms);
    std::sort(ms.begin(), ms.end());
    p.median_ms = ms[ms.size() / 2];
    p.min_ms = ms.front();
    p.max_ms = ms.back();
    p.residual_rms_pct = costResidualRmsPct(s, cost);
    for (const Sample& x : s) {
        p.samples_ms_px_tri.push_back({x.ms, x.pixels, x.triangles});
        p.samples_fragments.push_back(x.fragments);
        p.samples_full_frame.push_back(x.full_frame ? 1 : 0);
    }
    return p;
}

}  // namespace

std::string costLawText(const PartCost& c) {
    std::string s = c.power_coef_ms > 0.0
                        ? fmt::format("{:.4g}·Mpx^{:.3f}·ktri^{:.3f}", c.power_coef_ms,
                                      c.px_exponent, c.tri_exponent)
                        : fmt::format("{:.3f} + {:.3f}·Mpx + {:.4f}·ktri", c.base_ms, c.ms_per_mpx,
                                      c.ms_per_ktri);
    if (c.power_coef_ms <= 0.0 && c.ms_per_mfrag > 0.0)
        s += fmt::format(" + {:.3f}·Mfrag ({:.2f} fragments a pixel)", c.ms_per_mfrag,
                         c.frag_per_px);
    if (c.full_frame_scale != 1.0)
        s += fmt::format("; whole frame {:.3f}×", c.full_frame_scale);
    return s;
}

std::string calibrationCacheKey(const CalibrateOptions& o) {
    // What the calibration measures and how; a cached calibration of another version is not reused.
    constexpr int kCalibrationVersion = 17;
    const std::string text =
        fmt::format("v{}|{}|{}|{}|{}|{}|{}", kCalibrationVersion, machineDescription(), o.profile,
                    o.scene, o.codec, o.lod_px, o.core);
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return fmt::format("{:016x}", h);
}

std::string calibrationCachePath(const CalibrateOptions& o) {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    const std::string base = xdg && *xdg     ? std::string(xdg)
                             : home && *home ? std::string(home) + "/.cache"
                                             : std::string("/tmp");
    return base + "/qvr/calibration-" + calibrationCacheKey(o) + ".toml";
}

namespace {
nlohmann::json corunJson(const Calibration::CoRun& c) {
    return {{"slowdown", c.slowdown},
            {"frame_alone_ms", c.alone_ms},
            {"frame_shared_ms", c.shared_ms},
            {"paired_frames", c.samples},
            {"ratio_p10", c.ratio_p10},
            {"ratio_p90", c.ratio_p90},
            {"note", c.note}};
}
}  // namespace

nlohmann::json Calibration::toJson() const {
    nlohmann::json parts_json = nlohmann::json::array();
    for (const CalibratedPart& p : parts)
        parts_json.push_back({{"name", p.name},
                              {"sample", p.what},
                              {"samples", p.samples},
                              {"base_ms", p.cost.base_ms},
                              {"ms_per_mpx", p.cost.ms_per_mpx},
                              {"ms_per_ktri", p.cost.ms_per_ktri},
                              {"law", p.cost.power_coef_ms > 0.0 ? "power" : "linear"},
                              {"power_coef_ms", p.cost.power_coef_ms},
                              {"px_exponent", p.cost.px_exponent},
                              {"tri_exponent", p.cost.tri_exponent},
                              {"ms_per_mfrag", p.cost.ms_per_mfrag},
                              {"frag_per_px", p.cost.frag_per_px},
                              {"full_frame_scale", p.cost.full_frame_scale},
                              {"median_ms", p.median_ms},
                              {"min_ms", p.min_ms},
                              {"max_ms", p.max_ms},
                              {"residual_rms_pct", p.residual_rms_pct},
                              {"samples_ms_px_tri", p.samples_ms_px_tri},
                              {"samples_fragments", p.samples_fragments},
                              {"samples_full_frame", p.samples_full_frame}});
    return {{"machine", machine},
            {"date", date},
            {"command", command},
            {"seconds", seconds},
            {"load_avg_before", load_avg_before},
            {"parts", parts_json},
            {"links", links},
            {"frame_overhead_ms", costs.frame_overhead_ms},
            {"scanout_record_ms", costs.scanout_record_ms},
            {"bits_per_px_at_1", costs.bits_per_px_at_1},
            {"bits_scale_exponent", costs.bits_scale_exponent},
            {"bits_outer_per_px_at_1", costs.bits_outer_per_px_at_1},
            {"bits_outer_scale_exponent", costs.bits_outer_scale_exponent},
            {"bits_samples", bits_samples},
            {"bits_mean_over_geometric", bits_mean_over_geometric},
            {"bits_full_frame_per_px", costs.bits_full_frame_per_px},
            {"bits_full_frame_samples", bits_full_frame_samples},
            {"bits_frame",
             {{"content_key", costs.bits_frame_key},
              {"middle_over_law", costs.bits_frame_middle},
              {"outer_over_law", costs.bits_frame_outer}}},
            {"keyframe_bits_ratio", costs.keyframe_bits_ratio},
            {"keyframe_outer_bits_ratio", costs.keyframe_outer_bits_ratio},
            {"padding_bits_ratio", costs.padding_bits_ratio},
            {"keyframe_periodic_bits_ratio", costs.keyframe_periodic_bits_ratio},
            {"padding_samples", padding_samples},
            {"codec_by_e1", codec_by_e1},
            {"packet_payload_bytes", costs.packet_payload_bytes},
            {"packet_overhead_bytes", costs.packet_overhead_bytes},
            {"corun_headset", corunJson(corun_headset)},
            {"corun_server", corunJson(corun_server)},
            {"speed_reference",
             {{"headset_frame_ms", costs.speed_reference_headset_ms},
              {"server_frame_ms", costs.speed_reference_server_ms},
              {"key", costs.speed_reference_key},
              {"note", speed_note},
              {"probes", [this] {
                   nlohmann::json a = nlohmann::json::array();
                   for (const SpeedSample& p : speed_probes)
                       a.push_back(
                           {{"headset_frame_ms", p.headset_ms}, {"server_frame_ms", p.server_ms}});
                   return a;
               }()}}}};
}

namespace {

// The frame-by-frame bits in a line: how many frames, and the middle's and outer's mean over
// the law in the motion's first second (frames up to 30) and after it, with their range.
std::string bitsByFrameText(const RuntimeCosts& c) {
    std::array<std::array<double, 3>, 4> acc{};  // {sum, min, max} middle/outer × early/late
    std::array<int, 2> n{};
    for (auto& a : acc)
        a = {0.0, 1e9, 0.0};
    for (size_t k = 0; k < c.bits_frame_key.size(); ++k) {
        if (c.bits_frame_key[k] == 0.0)
            continue;
        const size_t late = k < 30 ? 0 : 1;
        ++n[late];
        for (size_t li = 0; li < 2; ++li) {
            const double f = li == 0 ? c.bits_frame_middle[k] : c.bits_frame_outer[k];
            auto& a = acc[li * 2 + late];
            a[0] += f;
            a[1] = std::min(a[1], f);
            a[2] = std::max(a[2], f);
        }
    }
    if (n[0] + n[1] == 0)
        return "none (the law alone)";
    auto part = [&](size_t late, const char* what) {
        if (n[late] == 0)
            return std::string();
        return fmt::format(
            "{} {} frames: middle {:.3f}x [{:.2f}, {:.2f}], outer {:.3f}x "
            "[{:.2f}, {:.2f}]",
            what, n[late], acc[late][0] / n[late], acc[late][1], acc[late][2],
            acc[2 + late][0] / n[late], acc[2 + late][1], acc[2 + late][2]);
    };
    std::string early = part(0, "frames < 30,"), later = part(1, "frames >= 30,");
    return early + (early.empty() || later.empty() ? "" : "; ") + later + " of the law";
}

}  // namespace

std::string Calibration::toToml() const {
    std::string s = fmt::format(
        "# qvr calibrate: this machine's runtime costs (docs/MODEL.md §8).\n# {}\n# {}, {:.0f} s, "
        "load average {:.2f} before\n",
        command, date, seconds, load_avg_before);
    s += "# machine: " + machine + "\n";
    for (const CalibratedPart& p : parts)
        s += fmt::format(
            "# {:14} {:3} samples ({}): median {:.2f} ms [{:.2f}, {:.2f}], {} ms, fit "
            "residual {:.0f}% RMS\n",
            p.name, p.samples, p.what, p.median_ms, p.min_ms, p.max_ms, costLawText(p.cost),
            p.residual_rms_pct);
    s += fmt::format(
        "# bits per layer pixel: middle {:.4f}·s^{:.3f}, outer {:.4f}·s^{:.3f}, over {} P-frames "
        "(the mean; {:.3f}x / {:.3f}x the geometric mean)\n",
        costs.bits_per_px_at_1, costs.bits_scale_exponent, costs.bits_outer_per_px_at_1,
        costs.bits_outer_scale_exponent, bits_samples, bits_mean_over_geometric[0],
        bits_mean_over_geometric[1]);
    s += fmt::format("# bits per whole-frame pixel (remote's layer): {:.4f}, over {} P-frames\n",
                     costs.bits_full_frame_per_px, bits_full_frame_samples);
    s += "# bits frame by frame on the calibration's motion: " + bitsByFrameText(costs) + "\n";
    s += fmt::format(
        "# key frame of a new encoder: {:.2f}x a P-frame's bits (middle), {:.2f}x (outer); "
        "periodic: {:.2f}x; padding beyond the snug canvas: {:.3f} of a layer pixel's bits per "
        "pixel, over {} P-frame pairs\n",
        costs.keyframe_bits_ratio, costs.keyframe_outer_bits_ratio,
        costs.keyframe_periodic_bits_ratio, costs.padding_bits_ratio, padding_samples);
    s += "# co-running, headset: " + corun_headset.note + "\n";
    s += "# co-running, server: " + corun_server.note + "\n";
    if (!speed_probes.empty())
        s += fmt::format(
            "# speed reference (the probe's headset/server frame, the mean of {}): {}\n",
            speed_probes.size(), speedProbesText(speed_probes));
    if (!speed_note.empty())
        s += "# " + speed_note + "\n";
    return s + runtimeCostsToml(costs);
}

namespace {
// The calibration's views: the default head motion and gaze over the span a default run covers
// (150 frames at 90 Hz, 1.7 s). In an enclosed level the BVH counts almost the whole scene in
// every view, so what a layer costs depends on what it sees at its level of detail, which the
// cost's features do not capture: sampling other seconds of the motion mispredicted the room's
// periphery layers by 2x (docs/MODEL.md §8).
double poseTimeMs(int k) {
    return 50.0 + 290.0 * k;
}
}  // namespace

// One frame of one side's work in a run, for the co-running measurement (step 5 of
// runCalibration) and the decode's cost where the headset decodes (step 3b). The server's: the
// middle and outer layers of both eyes rendered with their holes, read back and each encoded in its
// own stream. The headset's: the fovea of both eyes rendered, the four streams' next frames
// decoded, UCA over the frame. At e1 = 10 degrees (where qvr and sw settle on the reference scenes)
// unless told; step k is the default motion's k-th refresh, with the first step's gaze throughout
// (so every layer keeps its size and any stream frame fits any step's plan).
class SideMix {
public:
    static constexpr double kE1Deg = 10.0;
    static constexpr int kStreamFrames = 24;  // the headset's streams, decoded round and round

    SideMix(Renderer& r, const HmdProfile& profile, const runtime::HeadsetInputs& inputs,
            const CodecConfig& codec, double e1_deg = kE1Deg)
        : m_r(r),
          m_profile(profile),
          m_inputs(inputs),
          m_codec(codec),
          m_e1_deg(e1_deg),
          m_planner(profile),
          m_compositor(profile, [] {
              ComposeOptions c;
              c.threads = 1;
              return c;
          }()) {}

    // The server's frame `step` (its encoders carry on from the frame before).
    Status server(int step) {
        const auto [head, plan] = view(step);
        for (int eye = 0; eye < 2; ++eye)
            for (int li = 0; li < 2; ++li) {
                const LayerKind kind = li == 0 ? LayerKind::kMiddle : LayerKind::kOuter;
                if (auto st = renderLayer(m_r, m_profile, plan, head, static_cast<Eye>(eye), kind,
                                          m_image, CameraOptions{}, LayerHoles{.enabled = true});
                    !st)
                    return makeError("layer render: " + st.error());
                auto& enc = m_encoders[static_cast<size_t>(eye * 2 + li)];
                if (!enc) {
                    auto made = makeVideoEncoder(m_codec);
                    if (!made)
                        return makeError("codec: " + made.error());
                    enc = std::move(*made);
                }
                auto out = enc->encode(m_image);
                if (!out)
                    return makeError("encode: " + out.error());
                m_canvas_px[static_cast<size_t>(eye * 2 + li)] =
                    double(enc->canvasWidth()) * double(enc->canvasHeight());
                if (m_recording)
                    m_streams[static_cast<size_t>(eye * 2 + li)].push_back(std::move(out->bytes));
            }
        return {};
    }
    // The headset's frame `step`: its streams are the server's first kStreamFrames frames,
    // coded once (the first call), then decoded in order, key frame first, round and round.
    Status headset(int step) {
        if (m_streams[0].empty()) {
            m_recording = true;
            for (int k = 0; k < kStreamFrames; ++k)
                if (auto st = server(k); !st)
                    return st;
            m_recording = false;
            m_encoders = {};
        }
        const auto [head, plan] = view(step);
        auto frame = std::make_shared<LayerFrame>();
        frame->plan = plan;
        frame->render_pose = head;
        for (int eye = 0; eye < 2; ++eye) {
            EyeLayerImages& imgs = frame->eyes[static_cast<size_t>(eye)];
            if (auto st = renderLayer(m_r, m_profile, plan, head, static_cast<Eye>(eye),
                                      LayerKind::kFovea, imgs.fovea);
                !st)
                return makeError("fovea render: " + st.error());
            for (int li = 0; li < 2; ++li) {
                const size_t sid = static_cast<size_t>(eye * 2 + li);
                auto& dec = m_decoders[sid];
                if (!dec) {
                    auto made = makeVideoDecoder(m_codec);
                    if (!made)
                        return makeError("codec: " + made.error());
                    dec = std::move(*made);
                }
                const auto& packets = m_streams[sid];
                const auto t0 = Clock::now();
                auto img =
                    dec->decode(packets[static_cast<size_t>(m_next_packet) % packets.size()]);
                const double ms = msSince(t0);
                if (!img)
                    return makeError("decode: " + img.error());
                if (m_decodes)
                    m_decodes->push_back({ms, m_canvas_px[sid], 0.0});
                (li == 0 ? imgs.middle : imgs.outer) = std::move(*img);
            }
        }
        ++m_next_packet;
        auto rep = m_compositor.present(frame, head, m_display);
        if (!rep)
            return makeError("UCA: " + rep.error());
        return {};
    }

    // Every decode's time from now on, against its canvas's pixels (nullptr: none).
    void recordDecodes(std::vector<CostSample>* sink) { m_decodes = sink; }
    // Fresh encoders and decoders, the streams from their first (key) frame: the frames after
    // are the same work as the last time after a restart (the speed probe's).
    void restart() {
        m_encoders = {};
        m_decoders = {};
        m_next_packet = 0;
    }

private:
    std::pair<Pose, LayerPlan> view(int step) const {
        const double t_ms = poseTimeMs(0) + 1000.0 / m_profile.refresh_hz * step;
        return {poseAt(m_inputs.traces.motion, t_ms),
                m_planner.plan(gazeAt(m_inputs.traces.gaze, poseTimeMs(0)), m_e1_deg)};
    }
    Renderer& m_r;
    const HmdProfile& m_profile;
    const runtime::HeadsetInputs& m_inputs;
    CodecConfig m_codec;
    double m_e1_deg;
    LayerPlanner m_planner;
    Compositor m_compositor;
    ImageRgba8 m_image;
    std::array<ImageRgba8, 2> m_display;
    std::array<std::unique_ptr<VideoEncoder>, 4> m_encoders;  // eye × {middle, outer}
    std::array<std::unique_ptr<VideoDecoder>, 4> m_decoders;
    std::array<std::vector<std::vector<uint8_t>>, 4> m_streams;
    std::array<double, 4> m_canvas_px{};  // each stream's canvas (its frames all share it)
    std::vector<CostSample>* m_decodes = nullptr;
    bool m_recording = false;
    int m_next_packet = 0;
};

// The speed probe (calibration.h SpeedProbe): the same headset and server frames every time,
// each after its key frame, their medians.
static Expected<SpeedSample> probeSpeed(SideMix& mix) {
    constexpr int n = SpeedProbe::kFrames;
    mix.restart();
    std::vector<double> headset, server;
    for (int k = 0; k <= n; ++k) {  // frame 0 decodes the streams' key frames, untimed
        const auto t0 = Clock::now();
        if (auto st = mix.headset(k); !st)
            return makeError("speed probe, headset frame: " + st.error());
        if (k > 0)
            headset.push_back(msSince(t0));
    }
    for (int k = 0; k < n + 2; ++k) {  // the key frame and the first P-frame untimed
        const auto t0 = Clock::now();
        if (auto st = mix.server(k); !st)
            return makeError("speed probe, server frame: " + st.error());
        if (k >= 2)
            server.push_back(msSince(t0));
    }
    auto median = [](std::vector<double>& v) {
        std::sort(v.begin(), v.end());
        return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    };
    return SpeedSample{median(headset), median(server)};
}

// The other core's work for the co-running measurement: `qvr corun-load` in a child process,
// pinned to its core, doing one side's frames (SideMix, `mix` "server" or "headset") while told
// to be busy ("1" on its stdin, "0" to pause); it exits when its stdin closes.
class CoRunLoad {
public:
    static Expected<std::unique_ptr<CoRunLoad>> start(const CalibrateOptions& o, int core,
                                                      const std::string& mix) {
        std::error_code ec;
        const std::string exe = std::filesystem::read_symlink("/proc/self/exe", ec).string();
        if (ec)
            return makeError("cannot find this executable: " + ec.message());
        int to_child[2], from_child[2];
        if (pipe2(to_child, O_CLOEXEC) != 0)
            return makeError(std::string("pipe: ") + std::strerror(errno));
        if (pipe2(from_child, O_CLOEXEC) != 0) {
            ::close(to_child[0]);
            ::close(to_child[1]);
            return makeError(std::string("pipe: ") + std::strerror(errno));
        }
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, to_child[0], STDIN_FILENO);
        posix_spawn_file_actions_adddup2(&actions, from_child[1], STDOUT_FILENO);
        std::vector<std::string> args{exe,         "corun-load",
                                      "--scene",   o.scene,
                                      "--profile", o.profile,
                                      "--lod-px",  fmt::format("{}", o.lod_px),
                                      "--core",    std::to_string(core),
                                      "--codec",   o.codec,
                                      "--mix",     mix};
        std::vector<char*> argv;
        for (std::string& a : args)
            argv.push_back(a.data());
        argv.push_back(nullptr);
        pid_t pid = -1;
        const int rc = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        ::close(to_child[0]);
        ::close(from_child[1]);
        auto load = std::unique_ptr<CoRunLoad>(new CoRunLoad(pid, to_child[1], from_child[0]));
        if (rc != 0) {
            load->m_pid = -1;
            return makeError("cannot start " + exe + ": " + std::strerror(rc));
        }
        // Its ready line, once the scene is loaded (a minute at most).
        std::string line;
        char c = 0;
        for (;;) {
            pollfd pfd{load->m_out, POLLIN, 0};
            if (::poll(&pfd, 1, 60'000) <= 0)
                return makeError("the load process was not ready within 60 s");
            if (::read(load->m_out, &c, 1) != 1)
                return makeError("the load process ended before it was ready");
            if (c == '\n')
                break;
            line += c;
        }
        if (line != "ready")
            return makeError("the load process: " + line);
        return load;
    }
    // Busy frames until told otherwise; the answer comes once the first frame under way after
    // "1" has finished, or at once after "0" (the current frame finishes first).
    Status setBusy(bool busy) {
        const char cmd[2] = {busy ? '1' : '0', '\n'};
        if (!writeTwo(cmd))
            return makeError("cannot write to the load process");
        char c = 0;
        pollfd pfd{m_out, POLLIN, 0};
        if (::poll(&pfd, 1, 60'000) <= 0 || ::read(m_out, &c, 1) != 1)
            return makeError("the load process did not answer");
        return {};
    }
    // One speed probe in the child (mix "probe"): its line "headset_ms server_ms".
    Expected<SpeedSample> probe() {
        if (!writeTwo("p\n"))
            return makeError("cannot write to the speed probe process");
        std::string line;
        for (char c = 0;;) {
            pollfd pfd{m_out, POLLIN, 0};
            if (::poll(&pfd, 1, 60'000) <= 0 || ::read(m_out, &c, 1) != 1)
                return makeError("the speed probe process did not answer");
            if (c == '\n')
                break;
            if (line.size() > 200)
                return makeError("the speed probe process answered garbage");
            line += c;
        }
        SpeedSample sample;
        if (std::sscanf(line.c_str(), "%lf %lf", &sample.headset_ms, &sample.server_ms) != 2 ||
            !(sample.headset_ms > 0.0) || !(sample.server_ms > 0.0))
            return makeError("the speed probe process: " + line);
        return sample;
    }
    void stop() {
        if (m_in >= 0)
            ::close(m_in);
        m_in = -1;
        if (m_pid > 0) {
            int status = 0;
            for (int k = 0; k < 500 && ::waitpid(m_pid, &status, WNOHANG) == 0; ++k)
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            if (::waitpid(m_pid, &status, WNOHANG) == 0) {
                ::kill(m_pid, SIGKILL);
                ::waitpid(m_pid, &status, 0);
            }
        }
        m_pid = -1;
    }
    ~CoRunLoad() {
        stop();
        if (m_out >= 0)
            ::close(m_out);
    }

private:
    CoRunLoad(pid_t pid, int in, int out) : m_pid(pid), m_in(in), m_out(out) {}
    // Two bytes to the child. One that died has closed its end: the write must fail with EPIPE,
    // not raise SIGPIPE and end the calibration, so SIGPIPE is blocked for this thread while it
    // writes, and one it raised is taken back.
    bool writeTwo(const char* bytes) {
        sigset_t pipe_set, old_set;
        sigemptyset(&pipe_set);
        sigaddset(&pipe_set, SIGPIPE);
        pthread_sigmask(SIG_BLOCK, &pipe_set, &old_set);
        const ssize_t written = ::write(m_in, bytes, 2);
        if (written != 2 && errno == EPIPE) {
            const timespec zero{0, 0};
            sigtimedwait(&pipe_set, nullptr, &zero);
        }
        pthread_sigmask(SIG_SETMASK, &old_set, nullptr);
        return written == 2;
    }
    pid_t m_pid;
    int m_in;
    int m_out;
};

// `qvr corun-load`: the child CoRunLoad starts.
int runCoRunLoad(const CalibrateOptions& o, const std::string& mix) {
    using namespace qvr::runtime;
    if (auto st = pinCurrentThread(o.core); !st) {
        std::printf("%s\n", st.error().c_str());
        return 2;
    }
    auto profile = runtimeProfileByName(o.profile);
    auto inputs = profile
                      ? loadHeadsetInputs(o.scene, "default", "model", profile->refresh_hz, 400, 7)
                      : Expected<HeadsetInputs>(makeError(profile.error()));
    if (!inputs) {
        std::printf("%s\n", inputs.error().c_str());
        return 2;
    }
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    auto renderer = glRendererFactory(gl)();
    if (!renderer || !(*renderer)->upload(*inputs->scene)) {
        std::printf("%s\n", renderer ? "cannot upload the scene" : renderer.error().c_str());
        return 2;
    }
    CodecConfig codec;
    codec.backend = o.codec;
    SideMix side(**renderer, *profile, *inputs, codec);
    if (mix == "probe") {
        // The speed probe (SpeedProbe): one probe per "p" line, its medians on one line.
        if (auto st = side.headset(0); !st) {  // shaders compiled, the headset's streams coded
            std::printf("%s\n", st.error().c_str());
            return 1;
        }
        std::printf("ready\n");
        std::fflush(stdout);
        for (char c = 0; ::read(STDIN_FILENO, &c, 1) == 1;) {
            if (c != 'p')
                continue;
            auto sample = probeSpeed(side);
            if (!sample) {
                std::printf("%s\n", sample.error().c_str());
                return 1;
            }
            std::printf("%.6f %.6f\n", sample->headset_ms, sample->server_ms);
            std::fflush(stdout);
        }
        return 0;  // the parent is done
    }
    const bool server = mix == "server";
    int step = 0;
    auto frame = [&] { return server ? side.server(step++) : side.headset(step++); };
    // The first frame before "ready": shaders compiled, the headset's streams coded.
    if (auto st = frame(); !st) {
        std::printf("%s\n", st.error().c_str());
        return 1;
    }
    std::printf("ready\n");
    std::fflush(stdout);
    bool busy = false;
    bool answer = false;
    for (;;) {
        pollfd pfd{STDIN_FILENO, POLLIN, 0};
        const int n = ::poll(&pfd, 1, busy ? 0 : 100);
        if (n > 0) {
            char c = 0;
            if (::read(STDIN_FILENO, &c, 1) != 1)
                return 0;  // the parent is done
            if (c == '0' || c == '1') {
                busy = c == '1';
                answer = true;
            }
        }
        if (busy) {
            if (auto st = frame(); !st)
                return 1;
        }
        if (answer) {  // after the first frame when busy: the load is under way
            std::printf("k");
            std::fflush(stdout);
            answer = false;
        }
    }
}

Expected<Calibration> runCalibration(const CalibrateOptions& o) {
    using namespace qvr::runtime;
    const auto t_start = Clock::now();
    Calibration cal;
    cal.load_avg_before = loadAverage1();
    cal.machine = machineDescription();
    cal.date = utcNow();
    auto profile = runtimeProfileByName(o.profile);
    if (!profile)
        return makeError("--profile: " + profile.error());
    if (o.core >= 0) {
        if (auto st = pinCurrentThread(o.core); !st)
            std::fprintf(stderr, "qvr calibrate: %s (running unpinned)\n", st.error().c_str());
    }
    // The poses: the default motion's first seconds, the seeded gaze model. These are not a
    // run's frames: no pipeline, no network, each part timed alone.
    const int n_poses = o.quick ? 3 : 6;
    auto inputs = loadHeadsetInputs(o.scene, "default", "model", profile->refresh_hz, 400, 7);
    if (!inputs)
        return makeError(inputs.error());
    GlRendererOptions gl;
    gl.lod_error_px = o.lod_px;
    auto renderer = glRendererFactory(gl)();
    if (!renderer)
        return makeError(renderer.error());
    if (auto st = (*renderer)->upload(*inputs->scene); !st)
        return makeError(st.error());
    Renderer& r = **renderer;
    const LayerPlanner planner(*profile);
    // The triangles a layer draws (render/renderer.h layerTriangles): the draw list as the
    // renderer builds it, at the same level of detail; the server's periphery layers with their
    // holes (RenderServerConfig::holes), as `qvr run`'s server draws them.
    auto draw_list = std::make_shared<DrawList>(buildDrawList(*inputs->scene));
    if (o.lod_px > 0.0f)
        buildLods(*draw_list, *inputs->scene);
    const LayerHoles holes{.enabled = true};
    auto drawnTriangles = [&](const LayerPlan& plan, const Pose& head, int eye, LayerKind kind) {
        return double(layerTriangles(*draw_list, *profile, plan, head, static_cast<Eye>(eye), kind,
                                     o.lod_px, CameraOptions{},
                                     kind == LayerKind::kFovea ? LayerHoles{} : holes));
    };
    // LIWC's ring counts as the runtime makes them (HeadsetConfig::cluster_ring_counts).
    WorkloadProbe probe(*profile, inputs->bvh);
    probe.useClusters(draw_list, o.lod_px);
    CodecConfig codec;
    codec.backend = o.codec;
    const double eye_px = double(profile->width_px) * profile->height_px;

    struct PoseSample {
        Pose head;
        Gaze gaze;
    };
    std::vector<PoseSample> poses;
    for (int k = 0; k < n_poses; ++k) {
        const double t_ms = poseTimeMs(k);
        PoseSample p;
        p.head = poseAt(inputs->traces.motion, t_ms);
        p.gaze = gazeAt(inputs->traces.gaze, t_ms);
        poses.push_back(std::move(p));
    }
    auto log = [&](const std::string& line) {
        if (o.verbose) {
            std::fputs(line.c_str(), stdout);
            std::fflush(stdout);
        }
    };

    // 1. The decision: the draw clusters' ring counts (and the pixel rings), both eyes — one pass
    // over the clusters whatever e1 is, so a constant.
    std::vector<Sample> decision;
    for (const PoseSample& p : poses)
        for (int rep = 0; rep < 5; ++rep) {
            const auto t0 = Clock::now();
            const WorkloadFrame wf = probe.frame(0, 0.0, p.head, p.gaze);
            decision.push_back({msSince(t0), 0.0, 0.0});
            (void)wf;
        }
    cal.costs.decision = fitPartCost(decision, {.use_px = false, .use_tri = false});
    cal.parts.push_back(
        summarise("decision", "cluster ring counts, both eyes", decision, cal.costs.decision));
    log(fmt::format("  decision: {} samples\n", decision.size()));

    // 2. The plan and bookkeeping of a frame.
    {
        std::vector<double> ms;
        for (const PoseSample& p : poses)
            for (double e1 : {3.0, 8.0, 15.0}) {
                const auto t0 = Clock::now();
                const LayerPlan plan = planner.plan(p.gaze, e1);
                ms.push_back(msSince(t0));
                (void)plan;
            }
        std::sort(ms.begin(), ms.end());
        cal.costs.frame_overhead_ms = ms[ms.size() / 2];
    }

    // 3. Headset render: fovea passes at several e1, and the full frame (local).
    std::vector<Sample> fovea;
    std::vector<Sample> server;
    std::vector<Sample> encode;
    std::vector<Sample> decode;
    std::vector<Sample> uca;
    const std::vector<double> e1s = o.quick ? std::vector<double>{3, 8, 15, 30}
                                            : std::vector<double>{2, 4, 6, 9, 13, 18, 25, 35};
    ImageRgba8 image;
    Compositor compositor(*profile, [] {
        ComposeOptions c;
        c.threads = 1;
        return c;
    }());
    std::array<ImageRgba8, 2> display;
    // Per layer size class, an encoder and a decoder that see successive frames (P-frames).
    struct Chain {
        std::unique_ptr<VideoEncoder> enc;
        std::unique_ptr<VideoDecoder> dec;
        int frames = 0;
    };
    std::array<Chain, 4> chains;                  // stream ids: eye × {middle, outer}
    std::array<std::vector<BitsSample>, 2> bits;  // middle (and whole frame), outer
    // Warm-up: llvmpipe compiles its shaders on first use.
    {
        const LayerPlan plan = planner.plan(poses[0].gaze, 10.0);
        for (LayerKind kind : {LayerKind::kFovea, LayerKind::kMiddle, LayerKind::kOuter})
            if (auto st = renderLayer(r, *profile, plan, poses[0].head, Eye::kLeft, kind, image);
                !st)
                return makeError("render: " + st.error());
    }
    // The machine's speed while it is measured: a probe now, one after the layers, one at the
    // end (SpeedProbe; their mean is the hardware file's speed reference). A probe that cannot
    // run leaves the file without a reference (no run probes against it), not the costs unmeasured.
    auto speed_probe = SpeedProbe::make(o);
    cal.speed_note = speed_probe ? "" : speed_probe.error();
    auto speed = [&] {
        if (!cal.speed_note.empty())
            return;
        auto sample = (*speed_probe)->measure();
        if (!sample) {
            cal.speed_note = sample.error();
            cal.speed_probes.clear();
            return;
        }
        cal.speed_probes.push_back(*sample);
        log(fmt::format("  speed probe {}: headset frame {:.2f} ms, server frame {:.2f} ms\n",
                        cal.speed_probes.size(), sample->headset_ms, sample->server_ms));
    };
    speed();
    // Consecutive frames (1/refresh apart, as a run's content advances) so the codec sees the
    // motion of a run. Each sequence starts fresh encoders (below): frame 0 is their key frame,
    // frame 1 the first P-frame, which refers to that key frame and costs ~25% fewer bits than
    // the P-frames after it (measured over 15 steps: the middle's 0.33 bits per pixel at step 1
    // against 0.40–0.48 from step 2 on, the outer's 0.25 against 0.29–0.35). The times are
    // sampled from frame 2 on; the bits come from the longer codec pass below.
    const int sequence = 6;
    const int first_sampled = 2;
    const double frame_ms = 1000.0 / profile->refresh_hz;
    for (size_t pi = 0; pi < poses.size(); ++pi) {
        const PoseSample& p0 = poses[pi];
        for (double e1 : e1s) {
            // Each sequence codes into fresh encoders, as a run's streams at a steady e1 do: one
            // chain carried across e1 kept a canvas sized for the largest layer it had seen
            // (docs/CODEC.md "Canvas policy") and charged its padding to the smaller layers, which
            // over-predicted a run's bits per pixel by 30–100%.
            chains = {};
            for (int step = 0; step < sequence; ++step) {
                const double t_ms = poseTimeMs(static_cast<int>(pi)) + frame_ms * step;
                PoseSample p = p0;
                p.head = poseAt(inputs->traces.motion, t_ms);
                p.gaze = gazeAt(inputs->traces.gaze, t_ms);
                const bool sampled = step >= first_sampled;
                const LayerPlan plan = planner.plan(p.gaze, e1);
                auto frame = std::make_shared<LayerFrame>();
                frame->plan = plan;
                frame->render_pose = p.head;
                double layer_px = 0.0;
                for (int eye = 0; eye < 2; ++eye) {
                    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
                    EyeLayerImages& imgs = frame->eyes[static_cast<size_t>(eye)];
                    layer_px += double(layers.fovea.pixels() + layers.middle.pixels() +
                                       layers.outer.pixels());
                    if (!layers.fovea.empty()) {
                        const auto t0 = Clock::now();
                        auto st = renderLayer(r, *profile, plan, p.head, static_cast<Eye>(eye),
                                              LayerKind::kFovea, imgs.fovea);
                        if (!st)
                            return makeError("fovea render: " + st.error());
                        const double ms = msSince(t0);
                        if (step == 0)
                            fovea.push_back({ms, double(layers.fovea.pixels()),
                                             drawnTriangles(plan, p.head, eye, LayerKind::kFovea),
                                             false, fragmentsOf(*st)});
                    }
                    for (int li = 0; li < 2; ++li) {
                        const bool middle = li == 0;
                        const LayerRect& rect = middle ? layers.middle : layers.outer;
                        if (rect.empty())
                            continue;
                        ImageRgba8& img = middle ? imgs.middle : imgs.outer;
                        const LayerKind kind = middle ? LayerKind::kMiddle : LayerKind::kOuter;
                        const auto t0 = Clock::now();
                        auto st = renderLayer(r, *profile, plan, p.head, static_cast<Eye>(eye),
                                              kind, img, CameraOptions{}, holes);
                        if (!st)
                            return makeError("layer render: " + st.error());
                        const double ms = msSince(t0);
                        server.push_back(
                            {ms, double(rect.pixels()), drawnTriangles(plan, p.head, eye, kind)});
                        Chain& ch = chains[static_cast<size_t>(eye * 2 + li)];
                        if (!ch.enc) {
                            auto e = makeVideoEncoder(codec);
                            auto d = makeVideoDecoder(codec);
                            if (!e || !d)
                                return makeError("codec: " + (e ? d.error() : e.error()));
                            ch.enc = std::move(*e);
                            ch.dec = std::move(*d);
                        }
                        auto enc = ch.enc->encode(img);
                        if (!enc)
                            return makeError("encode: " + enc.error());
                        const auto t1 = Clock::now();
                        auto dec = ch.dec->decode(enc->bytes);
                        const double dec_ms = msSince(t1);
                        if (!dec)
                            return makeError("decode: " + dec.error());
                        (void)dec_ms;  // the decode's cost: step 3b, where the headset decodes
                    }
                }
                // UCA over the frame just rendered.
                const auto t0 = Clock::now();
                auto rep = compositor.present(frame, p.head, display);
                const double uca_ms = msSince(t0);
                if (!rep)
                    return makeError("UCA: " + rep.error());
                if (sampled)
                    uca.push_back({uca_ms, layer_px, 0});
            }
        }
        log(fmt::format("  pose {}/{}: fovea, periphery layers, codec, UCA\n", pi + 1,
                        poses.size()));
    }
    // The full frame: local's render and remote's server layer, and UCA over a full-resolution
    // layer (local's fovea, remote's whole frame), at every pose (~0.1-0.2 s a view). Their
    // median is the whole frame's scale: from the 4 samples of 2 poses (2 in --quick) one slow
    // moment of the host moved it from 1.02 to 1.14 between two calibrations of the room three
    // hours apart, and local's predicted FPS 13-18% low in every run after (docs/MODEL.md §8).
    speed();
    ScanoutRecorder video_stand_in(*profile, 1, false, /*keep=*/false);
    video_stand_in.reserve(1);
    std::vector<double> video_copy;
    for (size_t pi = 0; pi < poses.size(); ++pi) {
        const PoseSample& p = poses[pi];
        const LayerPlan full = planner.plan(p.gaze, 180.0);
        auto frame = std::make_shared<LayerFrame>();
        frame->plan = full;
        frame->render_pose = p.head;
        for (int eye = 0; eye < 2; ++eye) {
            ImageRgba8& img = frame->eyes[static_cast<size_t>(eye)].fovea;
            const auto t0 = Clock::now();
            auto st = renderLayer(r, *profile, full, p.head, static_cast<Eye>(eye),
                                  LayerKind::kFovea, img);
            if (!st)
                return makeError("full render: " + st.error());
            const double ms = msSince(t0);
            const double tris = drawnTriangles(full, p.head, eye, LayerKind::kFovea);
            fovea.push_back({ms, eye_px, tris, true, fragmentsOf(*st)});
            // The server's whole-frame layer is the same view at scale 1.
            server.push_back({ms, eye_px, tris, true});
        }
        for (int rep_i = 0; rep_i < 2; ++rep_i) {
            const auto t0 = Clock::now();
            auto rep = compositor.present(frame, p.head, display);
            if (!rep)
                return makeError("UCA: " + rep.error());
            uca.push_back({msSince(t0), 2.0 * eye_px, 0});
            // The display video's copy (`qvr run --video`): every design's headset copies its
            // scan-out at a quarter resolution right after UCA wrote it (ScanoutRecorder; its
            // stand-in for the designs not kept). Timed back to back over one display it read
            // 0.29 ms, where a run's headset paid 1.05: the display must be the one UCA just
            // wrote, as in a run.
            const auto t1 = Clock::now();
            video_stand_in.onScanout(runtime::FrameTelemetry{}, full, display);
            video_copy.push_back(msSince(t1));
        }
        log(fmt::format("  full frame {}/{}\n", pi + 1, poses.size()));
    }
    std::sort(video_copy.begin(), video_copy.end());
    cal.costs.scanout_record_ms = video_copy[video_copy.size() / 2];
    log(fmt::format("  display video copy after UCA: {:.2f} ms a frame (median of {})\n",
                    cal.costs.scanout_record_ms, video_copy.size()));
    // The codec's bits, as a run at a steady e1 spends them: one encoder per stream carried over
    // the consecutive frames of a default run's span (its motion's first 120 frames, 1/refresh
    // apart), P-frames from the run's warm-up (10 frames) on. The six-frame sequences above, each
    // from fresh encoders, saw only the first P-frames after a key frame and under-predicted a
    // steady run's periphery by 12–14% (docs/MODEL.md §8, calibration version 6).
    // Beside each stream's encoder runs a second one fed the same frames after one first image
    // 1.25× as wide and high, so it codes them into a larger canvas, as a run's stream does after
    // e1 grew: per frame, its bytes over the first one's give the cost of padding (the canvas
    // model's padding_bits_ratio); each chain's first frame, its IDR, over the median of its
    // P-frames gives the key-frame ratio (calibration version 7).
    struct PadSample {
        double extra, ratio;  // canvas pixels over the snug canvas's − 1; bytes over the snug's
    };
    std::vector<PadSample> pad;
    auto median = [](std::vector<double> v) {  // 0 for none
        if (v.empty())
            return 0.0;
        std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    auto mean = [](const std::vector<double>& v) {  // 0 for none
        double sum = 0.0;
        for (double x : v)
            sum += x;
        return v.empty() ? 0.0 : sum / double(v.size());
    };
    std::array<std::vector<double>, 2> key_ratio;  // a new encoder's IDR: middle, outer
    std::vector<double> periodic_ratio;            // the IDR at keyint_frames, both kinds
    nlohmann::json codec_by_e1 = nlohmann::json::array();
    // The motion frames the codec pass codes (the frame-by-frame bits below are kept for them).
    const int bits_frames = o.quick ? 40 : 120;
    {
        // One frame past keyint_frames when the pass reaches it: the periodic IDR of a running
        // stream costs less than a new encoder's first frame (3.9× against 7× a P-frame at
        // e1 = 5°, measured in a default run).
        const int pass_frames = codec.keyint_frames == bits_frames ? bits_frames + 1 : bits_frames;
        const int warmup = 10;
        std::array<Chain, 4> padded;
        ImageRgba8 big;
        for (double e1 : e1s) {
            chains = {};
            padded = {};
            std::array<double, 4> idr_bytes{};
            std::array<double, 4> periodic_bytes{};
            std::array<std::vector<double>, 4> p_bytes;
            std::array<std::vector<double>, 2> bits_px;  // this e1's P-frames: middle, outer
            std::array<double, 2> scale{};
            for (int step = 0; step < pass_frames; ++step) {
                // As `qvr run` times its frame `step`: the frame-by-frame bits below apply where
                // the head poses agree.
                const double t_ms = contentTimeMs(step, profile->refresh_hz);
                const Pose head = poseAt(inputs->traces.motion, t_ms);
                const Gaze gaze = gazeAt(inputs->traces.gaze, t_ms);
                const LayerPlan plan = planner.plan(gaze, e1);
                for (int eye = 0; eye < 2; ++eye) {
                    const EyeLayers& layers = plan.eyes[static_cast<size_t>(eye)];
                    for (int li = 0; li < 2; ++li) {
                        const bool middle = li == 0;
                        const LayerRect& rect = middle ? layers.middle : layers.outer;
                        if (rect.empty())
                            continue;
                        const LayerKind kind = middle ? LayerKind::kMiddle : LayerKind::kOuter;
                        if (auto st = renderLayer(r, *profile, plan, head, static_cast<Eye>(eye),
                                                  kind, image, CameraOptions{}, holes);
                            !st)
                            return makeError("layer render: " + st.error());
                        Chain& ch = chains[static_cast<size_t>(eye * 2 + li)];
                        if (!ch.enc) {
                            auto e = makeVideoEncoder(codec);
                            if (!e)
                                return makeError("codec: " + e.error());
                            ch.enc = std::move(*e);
                        }
                        auto enc = ch.enc->encode(image);
                        if (!enc)
                            return makeError("encode: " + enc.error());
                        // The encoder's time per pixel of the canvas it codes (the model charges
                        // the canvas), in a running stream: the six-frame sequences above saw
                        // only the first P-frames after a key frame, which carry 25-40% fewer
                        // bits (calibration version 12). Every third frame.
                        if (step >= warmup && step < bits_frames && step % 3 == 0 &&
                            !enc->is_keyframe && !enc->bytes.empty())
                            encode.push_back(
                                {enc->encode_ms,
                                 double(ch.enc->canvasWidth()) * double(ch.enc->canvasHeight()),
                                 0});
                        const size_t sid = static_cast<size_t>(eye * 2 + li);
                        if (step == 0 && enc->is_keyframe)
                            idr_bytes[sid] = double(enc->bytes.size());
                        if (step > 0 && step == codec.keyint_frames && enc->is_keyframe)
                            periodic_bytes[sid] = double(enc->bytes.size());
                        if (step >= bits_frames)
                            continue;  // only the periodic IDR is taken from the extra frame
                        if (step >= warmup && !enc->is_keyframe && !enc->bytes.empty()) {
                            bits_px[size_t(li)].push_back(8.0 * double(enc->bytes.size()) /
                                                          double(rect.pixels()));
                            scale[size_t(li)] = rect.scale;
                            bits[middle ? 0 : 1].push_back({rect.scale, double(rect.pixels()),
                                                            8.0 * double(enc->bytes.size()), step});
                            p_bytes[sid].push_back(double(enc->bytes.size()));
                        }
                        Chain& pc = padded[sid];
                        if (!pc.enc) {
                            auto e = makeVideoEncoder(codec);
                            if (!e)
                                return makeError("codec: " + e.error());
                            pc.enc = std::move(*e);
                            // The first image: the layer in the top-left of one 1.25× larger.
                            big.resize(image.width() * 5 / 4, image.height() * 5 / 4);
                            for (int y = 0; y < image.height(); ++y)
                                std::copy_n(image.row(y), image.strideElems(), big.row(y));
                            if (auto first = pc.enc->encode(big); !first)
                                return makeError("encode: " + first.error());
                        }
                        auto penc = pc.enc->encode(image);
                        if (!penc)
                            return makeError("encode: " + penc.error());
                        const double snug_px =
                            double(ch.enc->canvasWidth()) * double(ch.enc->canvasHeight());
                        const double extra = double(pc.enc->canvasWidth()) *
                                                 double(pc.enc->canvasHeight()) /
                                                 std::max(1.0, snug_px) -
                                             1.0;
                        if (step >= warmup && !enc->is_keyframe && !penc->is_keyframe &&
                            !enc->bytes.empty() && extra > 0.05)
                            pad.push_back(
                                {extra, double(penc->bytes.size()) / double(enc->bytes.size())});
                    }
                }
            }
            std::array<double, 4> open_r{}, periodic_r{};
            for (size_t sid = 0; sid < 4; ++sid) {
                std::vector<double>& v = p_bytes[sid];
                if (v.empty())
                    continue;
                // Over the mean P-frame, the scale the bits law now has (fitBitsLaw).
                const double p_mean = mean(v);
                if (idr_bytes[sid] > 0.0) {
                    open_r[sid] = idr_bytes[sid] / p_mean;
                    key_ratio[sid % 2].push_back(open_r[sid]);
                }
                if (periodic_bytes[sid] > 0.0) {
                    periodic_r[sid] = periodic_bytes[sid] / p_mean;
                    periodic_ratio.push_back(periodic_r[sid]);
                }
            }
            codec_by_e1.push_back({{"e1_deg", e1},
                                   {"middle_scale", scale[0]},
                                   {"middle_bits_per_px_median", median(bits_px[0])},
                                   {"outer_scale", scale[1]},
                                   {"outer_bits_per_px_median", median(bits_px[1])},
                                   {"keyframe_ratio_per_stream", open_r},
                                   {"periodic_keyframe_ratio_per_stream", periodic_r}});
            log(fmt::format("  codec: {} frames at e1 = {} deg\n", bits_frames, e1));
        }
    }
    // The canvas the runtime's encoders use, and what its key frames and padding cost.
    cal.costs.canvas_align_px = codec.canvas_align_px;
    cal.costs.canvas_headroom = codec.canvas_headroom;
    cal.costs.canvas_shrink_ratio = codec.canvas_shrink_ratio;
    cal.costs.canvas_shrink_after_frames = codec.canvas_shrink_after_frames;
    cal.costs.keyint_frames = codec.keyint_frames;
    cal.costs.keyframe_bits_ratio = median(key_ratio[0]);
    cal.costs.keyframe_outer_bits_ratio = median(key_ratio[1]);
    cal.costs.keyframe_periodic_bits_ratio = median(periodic_ratio);
    cal.codec_by_e1 = std::move(codec_by_e1);
    // remote's whole frame (one layer per eye at scale 1) in its own codec pass: the layers'
    // law, fitted at scales ~2.5–12 and taken to scale 1, put 0.27 bits on a whole-frame pixel
    // where a default run's remote frames carried 0.126 (2026-11-26), and predicted remote's
    // bytes 2.2x too high. Consecutive frames of the run's span from its warm-up on, fresh
    // encoders (the first is their key frame). P-frames from the encoder's seventh frame on: the
    // first P-frames after a key frame are cheap while x264's rate control settles (a default
    // run's remote frames 1, 2, 3 after its key frame: 0.076, 0.098, 0.113 bits a pixel, then
    // 0.12–0.127), and the layers' pass above likewise skips its first 10 frames.
    {
        const int steps = o.quick ? 12 : 18;
        const int ramp = 6;
        const int warmup = 10;
        std::array<std::unique_ptr<VideoEncoder>, 2> enc;
        std::vector<double> full_bits;
        for (int step = 0; step < steps; ++step) {
            const double t_ms = frame_ms * (warmup + step);
            const Pose head = poseAt(inputs->traces.motion, t_ms);
            const LayerPlan full = planner.plan(gazeAt(inputs->traces.gaze, t_ms), 180.0);
            for (int eye = 0; eye < 2; ++eye) {
                if (auto st = renderLayer(r, *profile, full, head, static_cast<Eye>(eye),
                                          LayerKind::kFovea, image);
                    !st)
                    return makeError("whole-frame render: " + st.error());
                auto& e = enc[static_cast<size_t>(eye)];
                if (!e) {
                    auto made = makeVideoEncoder(codec);
                    if (!made)
                        return makeError("codec: " + made.error());
                    e = std::move(*made);
                }
                auto out = e->encode(image);
                if (!out)
                    return makeError("whole-frame encode: " + out.error());
                if (step >= ramp && !out->is_keyframe) {
                    full_bits.push_back(8.0 * double(out->bytes.size()) /
                                        (double(image.width()) * double(image.height())));
                    // Its encode, against its canvas: the layers' law taken from their ~0.1 Mpx
                    // canvases to a whole frame's 5 Mpx one charged remote's encodes 81 ms a
                    // frame where a default run's took 63 (version 17): the whole frame gets
                    // its own scale, as its render does.
                    encode.push_back({out->encode_ms,
                                      double(e->canvasWidth()) * double(e->canvasHeight()), 0,
                                      true});
                }
            }
        }
        // The mean, as for the layers' law: the model's bytes per frame are a mean.
        cal.costs.bits_full_frame_per_px = mean(full_bits);
        cal.bits_full_frame_samples = static_cast<int>(full_bits.size());
        log(fmt::format("  whole frame codec: {} P-frames\n", full_bits.size()));
    }
    // 3b. The decode where the headset decodes: in a headset frame (SideMix), after the
    // previous frame's UCA and this frame's fovea, whose memory traffic has evicted the decoder's
    // pictures from the caches. Timed right after its own encode (versions 1-11), a layer's
    // decode took 0.3 ms where a run's headset took 0.74 ms over layers of the same size and
    // bits, 2.4x (docs/MODEL.md §8, calibration version 12). Per canvas pixel, P-frames only.
    {
        const std::vector<double> decode_e1s =
            o.quick ? std::vector<double>{4, 10, 20} : std::vector<double>{3, 5, 8, 12, 18, 28};
        const int frames = o.quick ? 8 : 12;  // under SideMix::kStreamFrames: no key frame
        for (double e1 : decode_e1s) {
            SideMix mix(r, *profile, *inputs, codec, e1);
            if (auto st = mix.headset(0); !st)  // codes the streams; decodes their key frames
                return makeError("decode pass: " + st.error());
            mix.recordDecodes(&decode);
            for (int k = 1; k <= frames; ++k)
                if (auto st = mix.headset(k); !st)
                    return makeError("decode pass: " + st.error());
        }
        log(fmt::format("  decode in headset frames: {} decodes at e1 {}\n", decode.size(),
                        fmt::join(decode_e1s, ", ")));
    }
    {
        // Least squares through the origin: bytes ratio − 1 = ρ · extra canvas share.
        double sxy = 0.0, sxx = 0.0;
        for (const PadSample& ps : pad) {
            sxy += ps.extra * (ps.ratio - 1.0);
            sxx += ps.extra * ps.extra;
        }
        cal.costs.padding_bits_ratio = sxx > 0.0 ? std::clamp(sxy / sxx, 0.0, 10.0) : 0.0;
        cal.padding_samples = static_cast<int>(pad.size());
    }
    // Bits per pixel: b·s^γ for the middle and the outer layer apart, γ from the logs, b from
    // the mean (sim/cost_fit.h fitBitsLaw).
    for (int li = 0; li < 2; ++li) {
        const BitsLaw law = fitBitsLaw(bits[static_cast<size_t>(li)]);
        if (law.bits_per_px_at_1 <= 0.0)
            continue;
        (li == 0 ? cal.costs.bits_per_px_at_1 : cal.costs.bits_outer_per_px_at_1) =
            law.bits_per_px_at_1;
        (li == 0 ? cal.costs.bits_scale_exponent : cal.costs.bits_outer_scale_exponent) =
            law.scale_exponent;
        cal.bits_mean_over_geometric[static_cast<size_t>(li)] =
            law.bits_per_px_at_1 / law.geometric_b;
        cal.bits_samples += static_cast<int>(bits[static_cast<size_t>(li)].size());
    }
    // Frame by frame: what each motion frame's layers spent, over every e1 and both eyes, over
    // what the law gives the same layers. The law is their mean; a 40-frame run measures the
    // motion's densest second, whose P-frames sit 12–15% over it (docs/MODEL.md §8 "Bits frame
    // by frame").
    {
        const int frames = bits_frames;
        std::array<std::vector<double>, 2> spent, law_bits;
        for (int li = 0; li < 2; ++li) {
            spent[size_t(li)].assign(size_t(frames), 0.0);
            law_bits[size_t(li)].assign(size_t(frames), 0.0);
            for (const BitsSample& b : bits[size_t(li)]) {
                if (b.frame < 0 || b.frame >= frames)
                    continue;
                spent[size_t(li)][size_t(b.frame)] += b.bits;
                law_bits[size_t(li)][size_t(b.frame)] +=
                    b.pixels * cal.costs.bitsPerPx(b.scale, li == 1);
            }
        }
        RuntimeCosts& rc = cal.costs;
        rc.bits_frame_key.assign(size_t(frames), 0.0);
        rc.bits_frame_middle.assign(size_t(frames), 1.0);
        rc.bits_frame_outer.assign(size_t(frames), 1.0);
        for (int k = 0; k < frames; ++k) {
            const size_t i = size_t(k);
            if (!(law_bits[0][i] > 0.0) || !(law_bits[1][i] > 0.0) || !(spent[0][i] > 0.0) ||
                !(spent[1][i] > 0.0))
                continue;  // the warm-up's frames, a key frame: the law alone
            rc.bits_frame_key[i] = double(frameContentKey(
                poseAt(inputs->traces.motion, contentTimeMs(k, profile->refresh_hz))));
            rc.bits_frame_middle[i] = std::clamp(spent[0][i] / law_bits[0][i], 0.05, 20.0);
            rc.bits_frame_outer[i] = std::clamp(spent[1][i] / law_bits[1][i], 0.05, 20.0);
        }
        // The hardware file holds only the frames measured: trailing law-only frames are dropped.
        while (!rc.bits_frame_key.empty() && rc.bits_frame_key.back() == 0.0) {
            rc.bits_frame_key.pop_back();
            rc.bits_frame_middle.pop_back();
            rc.bits_frame_outer.pop_back();
        }
    }
    // The render passes may follow the power law (llvmpipe's fovea pass is not linear over
    // 3 kpx … 4 Mpx); the whole frame gets its own scale (MODEL.md §8).
    const CostFitOptions render_fit{.use_px = true, .use_tri = true, .allow_power = true};
    const CostFitOptions px_only{.use_px = true, .use_tri = false, .allow_power = false};
    // The fovea pass charges its shaded fragments (its overdraw) and triangles, not its pixels:
    // over the same samples the pixels' law left 17–20% RMS, two poses with the same pixels and
    // triangles 2× apart; the fragments' 7% (docs/MODEL.md §8, "Fragments"; version 16).
    CostFitOptions fovea_fit = render_fit;
    fovea_fit.use_frag = true;
    cal.costs.fovea = fitPartCost(fovea, fovea_fit);
    cal.costs.server_render = fitPartCost(server, render_fit);
    cal.costs.encode = fitPartCost(encode, px_only);
    cal.costs.decode = fitPartCost(decode, px_only);
    cal.costs.uca = fitPartCost(uca, px_only);
    cal.parts.push_back(
        summarise("fovea/local", "one eye's fovea or full-frame pass", fovea, cal.costs.fovea));
    cal.parts.push_back(summarise("server render",
                                  "one periphery or whole-frame layer (ktri drawn: LOD, holes)",
                                  server, cal.costs.server_render));
    cal.parts.push_back(summarise("encode",
                                  "one layer or whole frame, P-frame, running stream (canvas px)",
                                  encode, cal.costs.encode));
    cal.parts.push_back(summarise("decode", "one stream, P-frame, in a headset frame (canvas px)",
                                  decode, cal.costs.decode));
    cal.parts.push_back(
        summarise("uca", "one frame, both eyes, per layer pixel read", uca, cal.costs.uca));

    // 4. The link: net's profiles and its packets' header.
    cal.costs.packet_payload_bytes = double(net::kMediaChunkBytes);
    cal.costs.packet_overhead_bytes = double(net::kMediaHeaderBytes);
    cal.links = nlohmann::json::object();
    for (const std::string& name : qvr::linkProfileNames()) {
        auto lc = qvr::parseLinkSpec(name);
        if (lc)
            cal.links[name] = {{"rate_bps", lc->rate_bps}, {"delay_ms", lc->delay_ms}};
    }
    // 5. The two cores at once. In a run the headset and the server work at the same time, each
    // on its core and in its own process; on a machine whose cores share memory bandwidth, a
    // physical core or a host's time, each is then slower than alone, which no part timed alone
    // shows. How much depends on what both do: a rasteriser beside a rasteriser (versions 9-11)
    // measured x1.00 on a 2-core KVM guest where a run's periphery layers took 1.15x their law
    // and its fovea 1.2x, and a streaming copy beside another 2.2x (docs/MODEL.md §8
    // "Co-running"). So each side's frames (SideMix) are timed on this core alone and beside
    // `qvr corun-load` doing the other side's frames on another core without pause: pairs of
    // blocks, alone then shared, over the same frames. A process, not a thread: llvmpipe
    // serialises the rasterisation of contexts that share its screen.
    {
        const int cores = onlineCores();
        const int other = cores > 1 ? (o.core == cores - 1 ? 0 : cores - 1) : -1;
        SideMix side(r, *profile, *inputs, codec);
        auto measure = [&](bool headset_side, Calibration::CoRun& out) -> Status {
            const char* self = headset_side ? "headset" : "server";
            const char* load_mix = headset_side ? "server" : "headset";
            if (other < 0) {
                out.note = "one core: no co-running to measure";
                return {};
            }
            auto load = CoRunLoad::start(o, other, load_mix);
            if (!load) {  // a load that cannot run leaves co-running unmeasured (x1)
                out.note = "not measured: " + load.error();
                return {};
            }
            auto frame = [&](int step) {
                return headset_side ? side.headset(step) : side.server(step);
            };
            if (auto st = frame(0); !st)  // warm-up (and the headset's streams)
                return makeError(std::string("co-run ") + self + " frame: " + st.error());
            // The slowdown comes and goes with what the host does: many pairs, their
            // geometric mean.
            const int pairs = o.quick ? 6 : 10;
            constexpr int kBlock = 6;
            std::vector<double> ratios, alone_all, shared_all;
            std::string load_error;
            for (int pair = 0; pair < pairs && load_error.empty(); ++pair) {
                std::array<std::vector<double>, 2> ms;
                for (int with = 0; with < 2 && load_error.empty(); ++with) {
                    if (auto st = (*load)->setBusy(with == 1); !st) {
                        load_error = st.error();
                        break;
                    }
                    for (int k = 0; k < kBlock; ++k) {
                        const auto t0 = Clock::now();
                        if (auto st = frame(1 + pair * kBlock + k); !st)
                            return makeError(std::string("co-run ") + self +
                                             " frame: " + st.error());
                        ms[static_cast<size_t>(with)].push_back(msSince(t0));
                    }
                }
                if (!load_error.empty())
                    break;
                for (size_t j = 0; j < ms[0].size(); ++j) {
                    ratios.push_back(ms[1][j] / std::max(1e-6, ms[0][j]));
                    alone_all.push_back(ms[0][j]);
                    shared_all.push_back(ms[1][j]);
                }
            }
            (*load)->stop();
            if (!load_error.empty() || ratios.empty()) {
                out.note = "not measured: the load process: " + load_error;
                return {};
            }
            double log_sum = 0.0;
            for (double x : ratios)
                log_sum += std::log(x);
            const double geo_mean = std::exp(log_sum / double(ratios.size()));
            std::sort(ratios.begin(), ratios.end());
            std::sort(alone_all.begin(), alone_all.end());
            std::sort(shared_all.begin(), shared_all.end());
            out.alone_ms = alone_all[alone_all.size() / 2];
            out.shared_ms = shared_all[shared_all.size() / 2];
            out.samples = static_cast<int>(ratios.size());
            out.ratio_p10 = ratios[ratios.size() / 10];
            out.ratio_p90 = ratios[ratios.size() * 9 / 10];
            out.slowdown = std::clamp(geo_mean, 1.0, 4.0);
            out.note = fmt::format(
                "{} frames (e1 = {:g} deg) {:.2f} ms alone, {:.2f} ms with core {} doing the "
                "{}'s (medians); slowdown x{:.3f} (geometric mean of {} paired frames, p10-p90 "
                "{:.2f}-{:.2f})",
                self, SideMix::kE1Deg, out.alone_ms, out.shared_ms, other, load_mix, out.slowdown,
                ratios.size(), out.ratio_p10, out.ratio_p90);
            return {};
        };
        if (auto st = measure(true, cal.corun_headset); !st)
            return makeError(st.error());
        log("  co-running, headset: " + cal.corun_headset.note + "\n");
        if (auto st = measure(false, cal.corun_server); !st)
            return makeError(st.error());
        log("  co-running, server: " + cal.corun_server.note + "\n");
        // Measured per side; the shared factor stays 1 (sim/hardware.h).
        cal.costs.corun_headset_slowdown = cal.corun_headset.slowdown;
        cal.costs.corun_server_slowdown = cal.corun_server.slowdown;
    }

    // The third speed probe, and the reference: the mean of the three.
    speed();
    if (!cal.speed_note.empty()) {
        cal.speed_note = "no speed reference: " + cal.speed_note;
        log("  " + cal.speed_note + "\n");
    } else {
        SpeedSample ref;
        for (const SpeedSample& p : cal.speed_probes) {
            ref.headset_ms += p.headset_ms / double(cal.speed_probes.size());
            ref.server_ms += p.server_ms / double(cal.speed_probes.size());
        }
        cal.costs.speed_reference_headset_ms = ref.headset_ms;
        cal.costs.speed_reference_server_ms = ref.server_ms;
        cal.costs.speed_reference_key = calibrationCacheKey(o);
        log(
            fmt::format("  speed reference: headset frame {:.2f} ms, server frame {:.2f} ms "
                        "(mean of {} probes: {})\n",
                        ref.headset_ms, ref.server_ms, cal.speed_probes.size(),
                        speedProbesText(cal.speed_probes)));
    }

    cal.seconds = std::chrono::duration<double>(Clock::now() - t_start).count();
    return cal;
}

struct SpeedProbe::Impl {
    std::unique_ptr<CoRunLoad> child;
};

SpeedProbe::SpeedProbe(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SpeedProbe::~SpeedProbe() = default;

Expected<std::unique_ptr<SpeedProbe>> SpeedProbe::make(const CalibrateOptions& o) {
    // A process of its own, pinned to o.core, the same at the calibration and at the run: taken
    // in the calibrating process's renderer, the probe read the headset frame 36.7-37.4 ms, and
    // 34.5-36.4 ms in the run's process minutes later, where the run's stages were not faster
    // (docs/MODEL.md §8 "The machine's speed at the run").
    auto child = CoRunLoad::start(o, std::max(o.core, 0), "probe");
    if (!child)
        return makeError("speed probe: " + child.error());
    auto impl = std::make_unique<Impl>();
    impl->child = std::move(*child);
    return std::unique_ptr<SpeedProbe>(new SpeedProbe(std::move(impl)));
}

Expected<SpeedSample> SpeedProbe::measure() {
    return m_impl->child->probe();
}

std::array<double, 2> speedProbesSpreadPct(const std::vector<SpeedSample>& probes) {
    std::array<double, 2> out = {0.0, 0.0};
    if (probes.size() < 2)
        return out;
    for (size_t side = 0; side < 2; ++side) {
        double lo = 1e300, hi = 0.0;
        for (const SpeedSample& p : probes) {
            const double v = side == 0 ? p.headset_ms : p.server_ms;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        out[side] = 100.0 * (hi / lo - 1.0);
    }
    return out;
}

std::string speedProbesText(const std::vector<SpeedSample>& probes) {
    std::string s;
    for (const SpeedSample& p : probes)
        s += fmt::format("{}{:.2f}/{:.2f}", s.empty() ? "" : ", ", p.headset_ms, p.server_ms);
    if (probes.size() < 2)
        return s + " ms headset/server";
    const auto sp = speedProbesSpreadPct(probes);
    const double spread = std::max(sp[0], sp[1]);
    return s + fmt::format(" ms headset/server; spread {:.0f}%{}", spread,
                           spread > kUnsteadySpeedPct
                               ? " (the machine was unsteady while it was measured: "
                                 "calibrate again on a steady one)"
                               : "");
}

}  // namespace qvr::experiment
