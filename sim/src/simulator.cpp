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

#include "qvr/controller/liwc.h"
#include "qvr/core/check.h"
#include "qvr/core/run_summary.h"
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
    if (t.policy == "liwc") {
        LiwcConfig cfg;
        // LIWC reads the link rate from the radio before any acknowledgement arrives.
        cfg.throughput_bps_initial = link_nominal_bps;
        return std::unique_ptr<FoveaPolicy>(std::make_unique<LiwcPolicy>(header, cfg));
    }
    return makeError("design '" + std::string(t.name) + "' names an unknown policy");
}

RunResult simulate(const WorkloadTrace& trace, const SimConfig& config, Link& link) {
    const DesignTraits& traits = traitsOf(config.design);
    const HardwareConfig& hw = config.hardware;
    const WorkloadHeader& header = trace.header;
    const CostModel truth(header, hw.gpu.render, link.meanGoodputBps());
    const LayerPlanner& planner = truth.planner();
    auto policy_or = makeDesignPolicy(config.design, header, link.nominalBps());
    QVR_CHECK_MSG(policy_or.ok(), "built-in design without a policy");
    std::unique_ptr<FoveaPolicy> policy = std::move(*policy_or);

    const int n_frames =
        std::max(0, std::min<int>(config.frames, static_cast<int>(trace.frames.size())));
    const double eye_px = static_cast<double>(header.profile.width_px) * header.profile.height_px;
    const double frame_px = 2.0 * eye_px;  // both eyes
    const GpuModel& g = hw.gpu.render;
    const GpuModel server{500.0, g.triangles_per_ms_at_500 * hw.remote.server_speedup,
                          g.pixels_per_ms_at_500 * hw.remote.server_speedup, g.setup_ms};
    const bool uses_remote = traits.split != Split::LocalOnly;
    const bool liwc = traits.policy == "liwc";
    const double gpu_dyn_w = hw.gpu.dynamicPowerW();
    const double gpu_static_w = hw.gpu.staticPowerW();

    GpuTimeline gpu;
    double cpu_free = 0.0, link_free = 0.0, server_free = 0.0, decoder_free = 0.0;
    double uca_free = 0.0;
    double previous_inputs_delay_ms = 0.0;
    // One remote fetch; for the static design `prefetch` holds the next frame's background,
    // requested one frame ahead.
    struct RemoteFetch {
        bool valid = false;
        double pose_ms = 0.0;  // when the pose the server renders for was sampled
        double request_ms = 0.0, ready_ms = 0.0, t_remote_ms = 0.0, net_ms = 0.0;
        double server_ms = 0.0, encode_ms = 0.0, decode_ms = 0.0, bytes = 0.0, goodput = 0.0;
    } prefetch;

    // One streamed remote fetch: render, encode, transmit and decode overlap (§2.3, [31, 34]).
    auto stream = [&](double pose_ms, double request_ms, double bytes, double server_ms,
                      double encode_ms, double decode_ms) {
        RemoteFetch p;
        p.valid = true;
        p.pose_ms = pose_ms;
        p.request_ms = request_ms;
        const double s = std::max({request_ms, link_free, server_free, decoder_free});
        const LinkTransfer tr = link.transfer(s, bytes);
        p.net_ms = tr.duration_ms;
        p.goodput = tr.goodput_bps;
        p.server_ms = server_ms;
        p.encode_ms = encode_ms;
        p.decode_ms = decode_ms;
        p.bytes = bytes;
        p.ready_ms = s + std::max({server_ms, encode_ms, p.net_ms, decode_ms});
        p.t_remote_ms = p.ready_ms - request_ms;
        link_free = s + p.net_ms;
        server_free = s + std::max(server_ms, encode_ms);
        decoder_free = s + decode_ms;
        return p;
    };
    auto decodeMs = [&](double pixels) {
        return pixels > 0.0 ? hw.remote.decode_overhead_ms + pixels / hw.remote.decoder_px_per_ms
                            : 0.0;
    };
    auto staticLocalMs = [&](const WorkloadFrame& f) {
        return g.setup_ms + f.static_split.fg_triangles / g.trianglesPerMs() +
               f.static_split.fg_screen_fraction * frame_px / g.pixelsPerMs();
    };
    auto staticRemote = [&](double pose_ms, double request_ms, const WorkloadFrame& f) {
        const double bg_tris = sumTotal(f.triangles_per_ring) - f.static_split.fg_triangles;
        const double server_ms = server.setup_ms +
                                 std::max(0.0, bg_tris) / server.trianglesPerMs() +
                                 frame_px / server.pixelsPerMs();
        // Colour and depth are two streams per eye on their own encoders.
        const double encode_ms = eye_px / hw.remote.encoder_px_per_ms;
        return stream(pose_ms, request_ms, f.static_split.bg_bytes + f.static_split.depth_bytes,
                      server_ms, encode_ms, decodeMs(2.0 * frame_px));
    };

    RunResult result;
    result.frames.reserve(static_cast<size_t>(n_frames));
    for (int n = 0; n < n_frames; ++n) {
        const WorkloadFrame& frame = trace.frames[static_cast<size_t>(n)];
        FrameRecord r;
        r.index = frame.index;
        const double cl_ms = hw.cpu.control_logic_ms +
                             (traits.software_control ? hw.cpu.software_control_ms : 0.0) +
                             (liwc ? hw.liwc.decision_ms : 0.0);
        const double lead_ms = cl_ms + hw.cpu.local_setup_ms;
        // Pacing: the runtime samples the pose as late as it can without the frame queueing
        // behind the previous one at the GPU or the link (a just-in-time frame start).
        // The display path (UCA, or the GPU's composition/ATW passes) is paced with the
        // previous frame's request-to-inputs delay as the estimate of this frame's.
        double start = cpu_free;
        if (traits.split != Split::RemoteOnly)
            start = std::max(start, gpu.earliestRenderStartMs(gpu.renderFreeMs()) - lead_ms);
        if (uses_remote)
            start = std::max(start, std::max({link_free, server_free, decoder_free}) - lead_ms);
        const double display_path_free = traits.uca ? uca_free : gpu.passFreeMs();
        start = std::max(start, display_path_free - lead_ms - previous_inputs_delay_ms);
        r.start_ms = start;
        const double ls_end = start + lead_ms;
        cpu_free = ls_end;
        r.request_ms = ls_end;

        Decision decision;
        if (policy)
            decision = policy->decide(frame);

        // What this frame renders locally and fetches remotely.
        double render_work_ms = 0.0;
        LayerPlan plan;
        FrameCost fcost;
        RemoteFetch remote;
        switch (traits.split) {
            case Split::LocalOnly:
                render_work_ms = truth.localOnlyMs(frame);
                r.shaded_pixels = frame_px;
                break;
            case Split::RemoteOnly: {
                const double bytes = bitsPerPixelAt(header, frame, 1.0) * frame_px / 8.0;
                const double server_ms =
                    server.setup_ms + sumTotal(frame.triangles_per_ring) / server.trianglesPerMs() +
                    frame_px / server.pixelsPerMs();
                remote = stream(start, ls_end, bytes, server_ms,
                                eye_px / hw.remote.encoder_px_per_ms, decodeMs(frame_px));
                r.shaded_pixels = frame_px;
                break;
            }
            case Split::Static: {
                render_work_ms = staticLocalMs(frame);
                remote = prefetch.valid ? prefetch : staticRemote(start, ls_end, frame);
                // Prefetch frame n+1's background now; the last frame has no successor.
                if (n + 1 < n_frames)
                    prefetch =
                        staticRemote(start, ls_end, trace.frames[static_cast<size_t>(n + 1)]);
                r.shaded_pixels = frame_px;
                break;
            }
            case Split::Foveated: {
                plan = planner.plan(frame.gaze, decision.e1_deg);
                fcost = truth.cost(frame, plan);
                render_work_ms = fcost.local_ms;
                r.e1_deg = plan.e1_deg;
                r.e2_deg = plan.e2_deg;
                const double mid_px = 2.0 * static_cast<double>(plan.middle_pixels);
                const double out_px = 2.0 * static_cast<double>(plan.outer_pixels);
                r.shaded_pixels = 2.0 * static_cast<double>(plan.fovea_pixels) + mid_px + out_px;
                if (plan.hasRemote()) {
                    // The server renders every triangle outside the fovea into the two layers.
                    const double tris =
                        std::max(0.0, sumTotal(frame.triangles_per_ring) - fcost.triangles_local);
                    const double server_ms = server.setup_ms + tris / server.trianglesPerMs() +
                                             (mid_px + out_px) / server.pixelsPerMs();
                    // Four streams (two layers × two eyes) encode and decode in parallel; the
                    // largest bounds each stage.
                    const double stream_px =
                        static_cast<double>(std::max(plan.middle_pixels, plan.outer_pixels));
                    const double decode_ms = hw.remote.decode_overhead_ms +
                                             (mid_px + out_px) / hw.remote.decoder_px_per_ms;
                    remote = stream(start, ls_end, fcost.bytes.total(), server_ms,
                                    stream_px / hw.remote.encoder_px_per_ms, decode_ms);
                }
                break;
            }
        }

        // Local rendering on the GPU.
        RenderSlot slot{ls_end, ls_end, 0, 0.0};
        if (render_work_ms > 0.0)
            slot = gpu.runRender(ls_end, render_work_ms, hw.gpu.preempt_overhead_ms);
        r.render_start_ms = slot.start_ms;
        r.render_end_ms = slot.end_ms;
        r.render_work_ms = render_work_ms;
        // What the headset measures: submission to completion, so time spent behind or
        // preempted by composition and ATW passes counts (Fig. 4-③).
        const double measured_from = config.t_local_from_submission ? ls_end : slot.start_ms;
        r.t_local_ms = render_work_ms > 0.0 ? slot.end_ms - measured_from : 0.0;
        r.preemptions = slot.preemptions;

        if (remote.valid) {
            r.remote_ready_ms = remote.ready_ms;
            r.t_remote_ms = remote.t_remote_ms;
            r.net_ms = remote.net_ms;
            r.server_render_ms = remote.server_ms;
            r.encode_ms = remote.encode_ms;
            r.decode_ms = remote.decode_ms;
            r.bytes = remote.bytes;
            r.goodput_bps = remote.goodput;
        } else {
            r.remote_ready_ms = slot.end_ms;
        }

        // Composition and ATW.
        const double inputs_ready = std::max(slot.end_ms, r.remote_ready_ms);
        double gpu_pass_ms = 0.0;
        if (traits.uca) {
            const int tile = hw.uca.tile_px;
            std::vector<UcaGroup> groups;
            double total_tiles = 0.0;
            for (const EyeLayers& eye : plan.eyes) {
                TileSplit ts = splitTiles(eye.fovea.rect, header.profile.width_px,
                                          header.profile.height_px, tile);
                groups.push_back({slot.end_ms, ts.interior});
                groups.push_back({r.remote_ready_ms, ts.periphery});
                groups.push_back({inputs_ready, ts.border});
                total_tiles += ts.interior + ts.periphery + ts.border;
            }
            // Tiles go to the units as their inputs land (§4.2: ATW starts on tiles that need
            // no composition before rendering completes).
            std::stable_sort(
                groups.begin(), groups.end(),
                [](const UcaGroup& a, const UcaGroup& b) { return a.ready_ms < b.ready_ms; });
            double t = uca_free;
            for (const UcaGroup& grp : groups) {
                if (grp.tiles <= 0.0)
                    continue;
                t = std::max(t, grp.ready_ms) + hw.uca.wallMs(grp.tiles);
            }
            uca_free = t;
            r.uca_ms = hw.uca.wallMs(total_tiles);
            r.display_ready_ms = std::max(t, inputs_ready);
            r.energy.uca_mj = hw.uca.power_w * total_tiles * hw.uca.tileMs();
        } else {
            if (traits.split == Split::Foveated || traits.split == Split::Static) {
                const double samples = traits.split == Split::Static
                                           ? hw.gpu.static_comp_samples_per_px
                                           : hw.gpu.comp_samples_per_px;
                r.comp_ms = hw.gpu.passMs(frame_px, samples);
            }
            r.atw_ms = hw.gpu.passMs(frame_px, hw.gpu.atw_samples_per_px);
            gpu_pass_ms = r.comp_ms + r.atw_ms;
            const GpuInterval iv = gpu.runPass(inputs_ready, gpu_pass_ms);
            r.display_ready_ms = iv.end_ms;
        }

        // Metrics (§5, §6.1).
        r.gpu_ms = render_work_ms + slot.overhead_ms + gpu_pass_ms;
        const double period_ms = std::max(r.gpu_ms, r.net_ms);
        r.fps = period_ms > 0.0 ? 1000.0 / period_ms : 0.0;
        // Motion-to-photon runs from the oldest pose whose pixels reach the display: for the
        // static design that is the pose the prefetched background was rendered for.
        const double pose_ms = remote.valid ? std::min(r.start_ms, remote.pose_ms) : r.start_ms;
        r.mtp_ms = hw.fixed.sensor_ms + (r.display_ready_ms - pose_ms) + hw.fixed.display_ms;
        previous_inputs_delay_ms = std::max(0.0, inputs_ready - r.request_ms);
        r.latency_ratio =
            (r.t_local_ms > 0.0 && r.t_remote_ms > 0.0) ? r.t_remote_ms / r.t_local_ms : 0.0;
        r.energy.gpu_dynamic_mj = gpu_dyn_w * r.gpu_ms;
        r.energy.gpu_static_mj = gpu_static_w * period_ms;
        r.energy.radio_mj = r.bytes * 8.0 * link.radio().energyPerBitNj(r.goodput_bps) * 1e-6;
        if (liwc)
            r.energy.liwc_mj = hw.liwc.power_w * period_ms;

        if (policy) {
            // The controller's own builder fills what the plan and cost say; the times and the
            // goodput are the simulated pipeline's, contention and queueing included.
            FrameMeasurement m =
                measureFrame(frame.index, plan, fcost, r.bytes > 0.0 ? r.goodput_bps : 0.0);
            m.t_local_ms = r.t_local_ms;
            m.t_remote_ms = r.t_remote_ms;
            policy->observe(m);
        }
        result.frames.push_back(r);
    }
    result.summary =
        summarize(result.frames, config, std::string(link.name()), header.profile.refresh_hz);
    return result;
}

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
    const double n = static_cast<double>(frames.size());
    std::vector<double> mtp;
    double period_sum = 0.0, e1_steady_sum = 0.0;
    int steady_n = 0;
    const int steady_from = steadyStateStart(s.frames);
    for (const FrameRecord& r : frames) {
        mtp.push_back(r.mtp_ms);
        s.mtp_ms_mean += r.mtp_ms / n;
        period_sum += std::max(r.gpu_ms, r.net_ms);
        s.bytes_per_frame_mean += r.bytes / n;
        s.pixels_per_frame_mean += r.shaded_pixels / n;
        s.energy_mean.gpu_dynamic_mj += r.energy.gpu_dynamic_mj / n;
        s.energy_mean.gpu_static_mj += r.energy.gpu_static_mj / n;
        s.energy_mean.radio_mj += r.energy.radio_mj / n;
        s.energy_mean.uca_mj += r.energy.uca_mj / n;
        s.energy_mean.liwc_mj += r.energy.liwc_mj / n;
        s.e1_deg_mean += r.e1_deg / n;
        s.t_local_ms_mean += r.t_local_ms / n;
        s.t_remote_ms_mean += r.t_remote_ms / n;
        s.render_wait_ms_mean += (r.t_local_ms - r.render_work_ms) / n;
        s.gpu_ms_mean += r.gpu_ms / n;
        s.net_ms_mean += r.net_ms / n;
        s.preemptions_per_frame += r.preemptions / n;
        if (r.index - frames.front().index >= steady_from) {
            e1_steady_sum += r.e1_deg;
            ++steady_n;
        }
    }
    s.mtp_ms_p99 = percentile(mtp, 99.0);
    s.fps_mean = period_sum > 0.0 ? 1000.0 * n / period_sum : 0.0;
    const double span_ms = frames.back().display_ready_ms - frames.front().display_ready_ms;
    s.fps_pipeline = span_ms > 0.0 ? 1000.0 * (n - 1.0) / span_ms : s.fps_mean;
    s.energy_mj_per_frame = s.energy_mean.total();
    s.e1_deg_steady = steady_n > 0 ? e1_steady_sum / steady_n : s.e1_deg_mean;
    std::vector<double> tail;
    for (size_t i = frames.size() > 30 ? frames.size() - 30 : 0; i < frames.size(); ++i)
        tail.push_back(frames[i].latency_ratio);
    s.latency_ratio_final = percentile(tail, 50.0);
    s.meets_refresh = s.fps_mean >= refresh_hz;
    return s;
}

}  // namespace qvr
