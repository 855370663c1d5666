// The per-frame pipeline of Fig. 4 as timed tasks on units (paper §2.3, §4, §5). Frame n:
//   CL (CPU) → [LIWC decision] → LS (CPU, issues the remote request)
//   → LR on the GPU (render priority)            ┐ in parallel
//   → RR ‖ encode ‖ transmit ‖ decode, streamed   ┘ T_remote = the largest (§2.3)
//   → composition + ATW: GPU passes that preempt rendering, or the UCA units
//   → display (5 ms); MTP adds the 2 ms sensor transfer.
// Frames overlap: frame n+1's CPU work and rendering start while frame n waits for its
// periphery, which is where the GPU contention of Fig. 4-③ comes from.
#include "qvr/sim/simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "qvr/controller/aimd.h"
#include "qvr/controller/liwc.h"
#include "qvr/core/check.h"
#include "qvr/core/run_summary.h"
#include "qvr/sim/display_path.h"
#include "qvr/sim/gpu_timeline.h"

namespace qvr {

namespace {

struct UcaGroup {
    double ready_ms;
    double tiles;
};

int tileSpan(int lo, int hi, int tile) {
    if (hi <= lo)
        return 0;
    return (hi - 1) / tile - lo / tile + 1;
}

// Tiles of one eye that the UCA can process once only the fovea is rendered (interior), once
// only the periphery has arrived (outside the fovea's bounding tiles) and once both are there
// (the fovea's border tiles blend two layers, Eq. 4).
struct TileSplit {
    double interior = 0.0;
    double border = 0.0;
    double periphery = 0.0;
};

TileSplit splitTiles(const PixelRect& fovea, int width_px, int height_px, int tile) {
    const double total = static_cast<double>(tileSpan(0, width_px, tile)) *
                         static_cast<double>(tileSpan(0, height_px, tile));
    const int tx = tileSpan(fovea.x0, fovea.x1, tile);
    const int ty = tileSpan(fovea.y0, fovea.y1, tile);
    const double touching = static_cast<double>(tx) * ty;
    const double interior = static_cast<double>(std::max(0, tx - 2)) * std::max(0, ty - 2);
    return {interior, touching - interior, total - touching};
}

}  // namespace

int steadyStateStart(int frames) {
    return std::min(100, frames / 3);
}

Expected<std::unique_ptr<FoveaPolicy>> makeDesignPolicy(Design design, const WorkloadHeader& header,
                                                        double link_nominal_bps) {
    const DesignTraits& t = traitsOf(design);
    if (t.policy.empty())
        return std::unique_ptr<FoveaPolicy>();
    if (t.policy == "fixed")
        return std::unique_ptr<FoveaPolicy>(std::make_unique<FixedPolicy>(5.0));
    if (t.policy == "sw")
        return makeSoftwareReactivePolicy(header);
    if (t.policy == "aimd")
        return makeAimdPolicy(header);
    if (t.policy == "liwc") {
        LiwcConfig cfg;
        // LIWC reads the link rate from the radio before any acknowledgement arrives.
        cfg.throughput_bps_initial = link_nominal_bps;
        return std::unique_ptr<FoveaPolicy>(std::make_unique<LiwcPolicy>(header, cfg));
    }
    return makeError("design '" + std::string(t.name) + "' names an unknown policy");
}

namespace {

// One streamed remote fetch; for the static design the next frame's background, requested one
// frame ahead.
struct RemoteFetch {
    bool valid = false;
    double pose_ms = 0.0;  // when the pose the server renders for was sampled
    double request_ms = 0.0, ready_ms = 0.0, t_remote_ms = 0.0, net_ms = 0.0;
    double server_ms = 0.0, encode_ms = 0.0, decode_ms = 0.0, bytes = 0.0, goodput = 0.0;
};

// What a frame renders locally and fetches remotely.
struct FrameWork {
    double render_work_ms = 0.0;
    LayerPlan plan;
    FrameCost cost;
    RemoteFetch remote;
};

// One run of the pipeline: the units' state between frames and the per-frame steps of Fig. 4.
class Pipeline {
public:
    Pipeline(const WorkloadTrace& trace, const SimConfig& config, Link& link)
        : m_trace(trace),
          m_config(config),
          m_link(link),
          m_traits(traitsOf(config.design)),
          m_hw(config.hardware),
          m_header(trace.header),
          m_truth(m_header, m_hw.gpu.render, link.meanGoodputBps()),
          m_gpu_model(m_hw.gpu.render),
          m_server{500.0, m_gpu_model.triangles_per_ms_at_500 * m_hw.remote.server_speedup,
                   m_gpu_model.pixels_per_ms_at_500 * m_hw.remote.server_speedup,
                   m_gpu_model.setup_ms},
          m_eye_px(static_cast<double>(m_header.profile.width_px) * m_header.profile.height_px),
          m_frame_px(2.0 * m_eye_px),
          m_liwc(m_traits.policy == "liwc") {
        if (config.oracle_policy && !m_traits.policy.empty()) {
            m_policy = makeOraclePolicy(m_header, m_truth);
        } else {
            auto policy_or = makeDesignPolicy(config.design, m_header, link.nominalBps());
            QVR_CHECK_MSG(policy_or.ok(), "built-in design without a policy");
            m_policy = std::move(*policy_or);
        }
    }

    FrameRecord step(int n, int n_frames);

private:
    // The CPU's work before the frame's rendering is issued: CL (with LIWC's or the software
    // controller's decision) and LS.
    double leadMs() const {
        return m_hw.cpu.control_logic_ms +
               (m_traits.software_control ? m_hw.cpu.software_control_ms : 0.0) +
               (m_liwc ? m_hw.liwc.decision_ms : 0.0) + m_hw.cpu.local_setup_ms;
    }
    double paceStart() const;
    FrameWork planWork(const WorkloadFrame& frame, const Decision& decision, double start,
                       double ls_end, int n, int n_frames);
    RemoteFetch stream(double pose_ms, double request_ms, double bytes, double server_ms,
                       double encode_ms, double decode_ms);
    RemoteFetch staticRemote(double pose_ms, double request_ms, const WorkloadFrame& f);
    double decodeMs(double pixels) const {
        return pixels > 0.0
                   ? m_hw.remote.decode_overhead_ms + pixels / m_hw.remote.decoder_px_per_ms
                   : 0.0;
    }
    double displayOnUca(FrameRecord& r, const LayerPlan& plan, double local_end_ms);
    double displayOnGpu(FrameRecord& r, double inputs_ready_ms);
    void finishFrame(FrameRecord& r, const FrameWork& work, double preempt_overhead_ms,
                     double gpu_pass_ms, double inputs_ready_ms);

    const WorkloadTrace& m_trace;
    const SimConfig& m_config;
    Link& m_link;
    const DesignTraits& m_traits;
    const HardwareConfig& m_hw;
    const WorkloadHeader& m_header;
    const CostModel m_truth;
    const GpuModel& m_gpu_model;
    const GpuModel m_server;
    const double m_eye_px;
    const double m_frame_px;  // both eyes
    const bool m_liwc;
    std::unique_ptr<FoveaPolicy> m_policy;

    GpuTimeline m_gpu;
    double m_cpu_free = 0.0, m_link_free = 0.0, m_server_free = 0.0, m_decoder_free = 0.0;
    double m_uca_free = 0.0;
    double m_previous_inputs_delay_ms = 0.0;
    double m_previous_start_ms = -std::numeric_limits<double>::infinity();
    RemoteFetch m_prefetch;
};

// One streamed remote fetch: render, encode, transmit and decode overlap (§2.3, [31, 34]).
RemoteFetch Pipeline::stream(double pose_ms, double request_ms, double bytes, double server_ms,
                             double encode_ms, double decode_ms) {
    RemoteFetch p;
    p.valid = true;
    p.pose_ms = pose_ms;
    p.request_ms = request_ms;
    const double s = std::max({request_ms, m_link_free, m_server_free, m_decoder_free});
    const LinkTransfer tr = m_link.transfer(s, bytes);
    p.net_ms = tr.duration_ms;
    p.goodput = tr.goodput_bps;
    p.server_ms = server_ms;
    p.encode_ms = encode_ms;
    p.decode_ms = decode_ms;
    p.bytes = bytes;
    p.ready_ms = s + std::max({server_ms, encode_ms, p.net_ms, decode_ms});
    p.t_remote_ms = p.ready_ms - request_ms;
    m_link_free = s + p.net_ms;
    m_server_free = s + std::max(server_ms, encode_ms);
    m_decoder_free = s + decode_ms;
    return p;
}

RemoteFetch Pipeline::staticRemote(double pose_ms, double request_ms, const WorkloadFrame& f) {
    const double bg_tris = sumTotal(f.triangles_per_ring) - f.static_split.fg_triangles;
    const double server_ms = m_server.setup_ms +
                             std::max(0.0, bg_tris) / m_server.trianglesPerMs() +
                             m_frame_px / m_server.pixelsPerMs();
    // Colour and depth are two streams per eye on their own encoders.
    const double encode_ms = m_eye_px / m_hw.remote.encoder_px_per_ms;
    return stream(pose_ms, request_ms, f.static_split.bg_bytes + f.static_split.depth_bytes,
                  server_ms, encode_ms, decodeMs(2.0 * m_frame_px));
}

// Pacing: the runtime samples the pose as late as it can without the frame queueing behind the
// previous one at the GPU or the link (a just-in-time frame start). The display path (UCA, or
// the GPU's composition/ATW passes) is paced with the previous frame's request-to-inputs delay
// as the estimate of this frame's. Paced to vsync, frames start at most once per refresh.
double Pipeline::paceStart() const {
    const double lead_ms = leadMs();
    double start = m_cpu_free;
    if (m_traits.split != Split::RemoteOnly)
        start = std::max(start, m_gpu.earliestRenderStartMs(m_gpu.renderFreeMs()) - lead_ms);
    if (m_traits.split != Split::LocalOnly)
        start = std::max(start, std::max({m_link_free, m_server_free, m_decoder_free}) - lead_ms);
    const double display_path_free = m_traits.uca ? m_uca_free : m_gpu.passFreeMs();
    start = std::max(start, display_path_free - lead_ms - m_previous_inputs_delay_ms);
    if (m_config.vsync_paced)
        start = std::max(start, m_previous_start_ms + 1000.0 / m_header.profile.refresh_hz);
    return start;
}
FrameWork Pipeline::planWork(const WorkloadFrame& frame, const Decision& decision, double start,
                             double ls_end, int n, int n_frames) {
    FrameWork w;
    switch (m_traits.split) {
        case Split::LocalOnly:
            w.render_work_ms = m_truth.localOnlyMs(frame);
            break;
        case Split::RemoteOnly: {
            const double bytes = bitsPerPixelAt(m_header, frame, 1.0) * m_frame_px / 8.0;
            const double server_ms =
                m_server.setup_ms + sumTotal(frame.triangles_per_ring) / m_server.trianglesPerMs() +
                m_frame_px / m_server.pixelsPerMs();
            w.remote = stream(start, ls_end, bytes, server_ms,
                              m_eye_px / m_hw.remote.encoder_px_per_ms, decodeMs(m_frame_px));
            break;
        }
        case Split::Static: {
            w.render_work_ms =
                m_gpu_model.setup_ms +
                frame.static_split.fg_triangles / m_gpu_model.trianglesPerMs() +
                frame.static_split.fg_screen_fraction * m_frame_px / m_gpu_model.pixelsPerMs();
            w.remote = m_prefetch.valid ? m_prefetch : staticRemote(start, ls_end, frame);
            // Prefetch frame n+1's background now; the last frame has no successor.
            if (n + 1 < n_frames)
                m_prefetch =
                    staticRemote(start, ls_end, m_trace.frames[static_cast<size_t>(n + 1)]);
            break;
        }
        case Split::Foveated: {
            w.plan = m_truth.planner().plan(frame.gaze, decision.e1_deg);
            w.cost = m_truth.cost(frame, w.plan);
            w.render_work_ms = w.cost.local_ms;
            if (!w.plan.hasRemote())
                break;
            const double mid_px = 2.0 * static_cast<double>(w.plan.middle_pixels);
            const double out_px = 2.0 * static_cast<double>(w.plan.outer_pixels);
            // The server renders every triangle outside the fovea into the two layers.
            const double tris =
                std::max(0.0, sumTotal(frame.triangles_per_ring) - w.cost.triangles_local);
            const double server_ms = m_server.setup_ms + tris / m_server.trianglesPerMs() +
                                     (mid_px + out_px) / m_server.pixelsPerMs();
            // Four streams (two layers × two eyes) encode and decode in parallel; the largest
            // bounds each stage.
            const double stream_px =
                static_cast<double>(std::max(w.plan.middle_pixels, w.plan.outer_pixels));
            const double decode_ms =
                m_hw.remote.decode_overhead_ms + (mid_px + out_px) / m_hw.remote.decoder_px_per_ms;
            w.remote = stream(start, ls_end, w.cost.bytes.total(), server_ms,
                              stream_px / m_hw.remote.encoder_px_per_ms, decode_ms);
            break;
        }
    }
    return w;
}

// Composition + ATW on the UCA units: tiles go to the units as their inputs land (§4.2: ATW
// starts on tiles that need no composition before rendering completes). Returns when the
// display image is ready.
double Pipeline::displayOnUca(FrameRecord& r, const LayerPlan& plan, double local_end_ms) {
    const int tile = m_hw.uca.tile_px;
    const double inputs_ready = std::max(local_end_ms, r.remote_ready_ms);
    std::vector<UcaGroup> groups;
    double total_tiles = 0.0;
    for (const EyeLayers& eye : plan.eyes) {
        TileSplit ts =
            splitTiles(eye.fovea.rect, m_header.profile.width_px, m_header.profile.height_px, tile);
        groups.push_back({local_end_ms, ts.interior});
        groups.push_back({r.remote_ready_ms, ts.periphery});
        groups.push_back({inputs_ready, ts.border});
        total_tiles += ts.interior + ts.periphery + ts.border;
    }
    std::stable_sort(groups.begin(), groups.end(),
                     [](const UcaGroup& a, const UcaGroup& b) { return a.ready_ms < b.ready_ms; });
    double t = m_uca_free;
    for (const UcaGroup& grp : groups) {
        if (grp.tiles <= 0.0)
            continue;
        t = std::max(t, grp.ready_ms) + m_hw.uca.wallMs(grp.tiles);
    }
    m_uca_free = t;
    r.uca_ms = m_hw.uca.wallMs(total_tiles);
    r.energy.uca_mj = m_hw.uca.power_w * total_tiles * m_hw.uca.tileMs();
    r.display_dram_bytes = ucaDramBytes(r.shaded_pixels, m_frame_px);
    r.display_dram_ms = dramMs(r.display_dram_bytes);
    return std::max(t, inputs_ready);
}

// Composition (collaborative designs) and ATW as GPU passes that preempt rendering. A pass takes
// its texture-filtering time or its DRAM time, whichever is longer. Returns the passes' time.
double Pipeline::displayOnGpu(FrameRecord& r, double inputs_ready_ms) {
    const MobileGpuConfig& gpu = m_hw.gpu;
    auto passMs = [&](double samples_per_px) {
        const double bytes = gpuPassDramBytes(m_frame_px, samples_per_px);
        r.display_dram_bytes += bytes;
        r.display_dram_ms += dramMs(bytes);
        return std::max(gpu.passMs(m_frame_px, samples_per_px),
                        gpu.pass_overhead_ms + dramMs(bytes));
    };
    if (m_traits.split == Split::Foveated || m_traits.split == Split::Static)
        r.comp_ms = passMs(m_traits.split == Split::Static ? gpu.static_comp_samples_per_px
                                                           : gpu.comp_samples_per_px);
    r.atw_ms = passMs(gpu.atw_samples_per_px);
    const double pass_ms = r.comp_ms + r.atw_ms;
    r.display_ready_ms = m_gpu.runPass(inputs_ready_ms, pass_ms).end_ms;
    return pass_ms;
}

// Metrics (§5, §6.1) and energy once the display image is ready; the policy learns the frame.
void Pipeline::finishFrame(FrameRecord& r, const FrameWork& work, double preempt_overhead_ms,
                           double gpu_pass_ms, double inputs_ready_ms) {
    r.gpu_ms = work.render_work_ms + preempt_overhead_ms + gpu_pass_ms;
    const double period_ms = std::max(r.gpu_ms, r.net_ms);
    r.fps = period_ms > 0.0 ? 1000.0 / period_ms : 0.0;
    const double vsync_ms = 1000.0 / m_header.profile.refresh_hz;
    r.display_ms = m_config.vsync_paced ? std::ceil(r.display_ready_ms / vsync_ms) * vsync_ms
                                        : r.display_ready_ms;
    // Motion-to-photon runs from the oldest pose whose pixels reach the display: for the static
    // design that is the pose the prefetched background was rendered for.
    const double pose_ms = work.remote.valid ? std::min(r.pose_ms, work.remote.pose_ms) : r.pose_ms;
    r.mtp_ms = m_hw.fixed.sensor_ms + (r.display_ms - pose_ms) + m_hw.fixed.display_ms;
    m_previous_inputs_delay_ms = std::max(0.0, inputs_ready_ms - r.request_ms);
    r.latency_ratio =
        (r.t_local_ms > 0.0 && r.t_remote_ms > 0.0) ? r.t_remote_ms / r.t_local_ms : 0.0;
    r.energy.gpu_dynamic_mj = m_hw.gpu.dynamicPowerW() * r.gpu_ms;
    r.energy.gpu_static_mj = m_hw.gpu.staticPowerW() * period_ms;
    if (r.bytes > 0.0) {
        r.radio_w = radioPowerW(m_link.radio(), r.goodput_bps);
        r.energy.radio_mj = radioEnergyMj(m_link.radio(), r.goodput_bps, r.net_ms);
    }
    if (m_liwc)
        r.energy.liwc_mj = m_hw.liwc.power_w * period_ms;
    if (m_policy) {
        // The controller's own builder fills what the plan and cost say; the times and the
        // goodput are the simulated pipeline's, contention and queueing included.
        FrameMeasurement m =
            measureFrame(r.index, work.plan, work.cost, r.bytes > 0.0 ? r.goodput_bps : 0.0);
        m.t_local_ms = r.t_local_ms;
        m.t_remote_ms = r.t_remote_ms;
        if (r.bytes > 0.0) {
            m.request_ms = r.request_ms;
            m.arrival_ms = r.remote_ready_ms;
        }
        m_policy->observe(m);
    }
}

FrameRecord Pipeline::step(int n, int n_frames) {
    const WorkloadFrame& frame = m_trace.frames[static_cast<size_t>(n)];
    FrameRecord r;
    r.index = frame.index;
    const double start = paceStart();
    r.pose_ms = start;
    m_previous_start_ms = start;
    const double ls_end = start + leadMs();
    m_cpu_free = ls_end;
    r.request_ms = ls_end;
    const Decision decision = m_policy ? m_policy->decide(frame) : Decision{};
    const FrameWork work = planWork(frame, decision, start, ls_end, n, n_frames);
    r.e1_deg = work.plan.e1_deg;
    r.e2_deg = work.plan.e2_deg;
    r.shaded_pixels =
        m_traits.split == Split::Foveated
            ? 2.0 * static_cast<double>(work.plan.fovea_pixels + work.plan.remotePixels())
            : m_frame_px;

    // Local rendering on the GPU.
    RenderSlot slot{ls_end, ls_end, 0, 0.0};
    if (work.render_work_ms > 0.0)
        slot = m_gpu.runRender(ls_end, work.render_work_ms, m_hw.gpu.preempt_overhead_ms);
    r.render_start_ms = slot.start_ms;
    r.render_end_ms = slot.end_ms;
    r.render_work_ms = work.render_work_ms;
    // What the headset measures: from the GPU's first cycle (default) or from submission.
    const double measured_from = m_config.t_local_from_submission ? ls_end : slot.start_ms;
    r.t_local_ms = work.render_work_ms > 0.0 ? slot.end_ms - measured_from : 0.0;
    r.preemptions = slot.preemptions;

    const RemoteFetch& remote = work.remote;
    r.remote_ready_ms = remote.valid ? remote.ready_ms : slot.end_ms;
    r.remote_requested = remote.valid;
    if (remote.valid) {
        r.t_remote_ms = remote.t_remote_ms;
        r.net_ms = remote.net_ms;
        r.server_render_ms = remote.server_ms;
        r.encode_ms = remote.encode_ms;
        r.decode_ms = remote.decode_ms;
        r.bytes = remote.bytes;
        r.goodput_bps = remote.goodput;
    }
    const double inputs_ready = std::max(slot.end_ms, r.remote_ready_ms);
    double gpu_pass_ms = 0.0;
    if (m_traits.uca)
        r.display_ready_ms = displayOnUca(r, work.plan, slot.end_ms);
    else
        gpu_pass_ms = displayOnGpu(r, inputs_ready);
    finishFrame(r, work, slot.overhead_ms, gpu_pass_ms, inputs_ready);
    return r;
}

}  // namespace

RunResult simulate(const WorkloadTrace& trace, const SimConfig& config, Link& link) {
    const int n_frames =
        std::max(0, std::min<int>(config.frames, static_cast<int>(trace.frames.size())));
    link.restart();  // a run is a session, from the trace's start
    Pipeline pipeline(trace, config, link);
    RunResult result;
    result.frames.reserve(static_cast<size_t>(n_frames));
    for (int n = 0; n < n_frames; ++n)
        result.frames.push_back(pipeline.step(n, n_frames));
    result.summary =
        summarize(result.frames, config, std::string(link.name()), trace.header.profile.refresh_hz);
    return result;
}

namespace {

// The statistics every pipeline shares, from core's summariser: the first warmup_frames left out,
// the MTP p99 exact however long the run (its frames are in memory anyway).
RunStats sharedStats(const std::vector<FrameRecord>& frames, int warmup_frames) {
    FrameSummarizer summarizer(warmup_frames, frames.size());
    for (const FrameRecord& r : frames)
        summarizer.add(r);
    return summarizer.finish();
}

}  // namespace

RunSummary summarize(const std::vector<FrameRecord>& frames, const SimConfig& config,
                     const std::string& net_name, double refresh_hz) {
    RunSummary s;
    s.bench = config.bench;
    s.design = std::string(traitsOf(config.design).name);
    s.gpu_mhz = config.hardware.gpu.render.freq_mhz;
    s.net = net_name;
    s.frames = static_cast<int>(frames.size());
    if (frames.empty())
        return s;
    const RunStats all = sharedStats(frames, 0);
    s.mtp_ms_mean = all.mtp_ms_mean;
    s.mtp_ms_p99 = all.mtp_ms_p99;
    s.bytes_per_frame_mean = all.bytes_per_frame_mean;
    s.e1_deg_mean = all.e1_deg_mean;
    s.e1_deg_steady = sharedStats(frames, steadyStateStart(s.frames)).e1_deg_mean;
    s.t_local_ms_mean = all.t_local_ms_mean;
    s.t_remote_ms_mean = all.t_remote_ms_mean;
    s.uca_ms_mean = all.uca_ms_mean;
    const double n = static_cast<double>(frames.size());
    double period_sum = 0.0;
    for (const FrameRecord& r : frames) {
        period_sum += std::max(r.gpu_ms, r.net_ms);
        s.pixels_per_frame_mean += r.shaded_pixels / n;
        s.energy_mean.gpu_dynamic_mj += r.energy.gpu_dynamic_mj / n;
        s.energy_mean.gpu_static_mj += r.energy.gpu_static_mj / n;
        s.energy_mean.radio_mj += r.energy.radio_mj / n;
        s.energy_mean.uca_mj += r.energy.uca_mj / n;
        s.energy_mean.liwc_mj += r.energy.liwc_mj / n;
        s.render_wait_ms_mean += (r.t_local_ms - r.render_work_ms) / n;
        s.gpu_ms_mean += r.gpu_ms / n;
        s.net_ms_mean += r.net_ms / n;
        s.preemptions_per_frame += r.preemptions / n;
        s.comp_ms_mean += r.comp_ms / n;
        s.atw_ms_mean += r.atw_ms / n;
        s.display_dram_mb_per_frame += r.display_dram_bytes * 1e-6 / n;
        s.display_dram_ms_mean += r.display_dram_ms / n;
        s.radio_w_max = std::max(s.radio_w_max, r.radio_w);
    }
    s.fps_mean = period_sum > 0.0 ? 1000.0 * n / period_sum : 0.0;
    // Core's rate of display needs two frames shown at different times.
    s.fps_pipeline = all.fps_mean > 0.0 ? all.fps_mean : s.fps_mean;
    s.energy_mj_per_frame = s.energy_mean.total();
    std::vector<double> tail;
    for (size_t i = frames.size() > 30 ? frames.size() - 30 : 0; i < frames.size(); ++i)
        tail.push_back(frames[i].latency_ratio);
    s.latency_ratio_final = percentile(tail, 50.0);
    s.meets_refresh = s.fps_mean >= refresh_hz;
    return s;
}

}  // namespace qvr
