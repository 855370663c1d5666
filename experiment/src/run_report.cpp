#include "qvr/experiment/run_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "qvr/experiment/host.h"
#include "qvr/runtime/session_outputs.h"

namespace qvr::experiment {

using namespace qvr::runtime;

std::optional<DesignLimits> designLimits(const std::vector<FrameTelemetry>& frames) {
    DesignLimits l;
    int n = 0, n_busy = 0, n_remote = 0;
    for (const FrameTelemetry& t : frames) {
        ++n;
        l.decision_ms += double(t.decision_ns - t.pose_ns) * 1e-6;
        l.local_ms += t.t_local_ms;
        l.uca_ms += t.uca_ms;
        if (t.headset_busy_ms > 0) {
            l.headset_busy_ms += t.headset_busy_ms;
            ++n_busy;
        }
        if (t.remote_requested) {
            l.t_remote_ms += t.t_remote_ms;
            ++n_remote;
        }
    }
    if (n == 0)
        return std::nullopt;
    l.headset_busy_ms = n_busy ? l.headset_busy_ms / n_busy : 0;
    l.t_remote_ms = n_remote ? l.t_remote_ms / n_remote : 0;
    l.decision_ms /= n;
    l.local_ms /= n;
    l.uca_ms /= n;
    if (l.t_remote_ms > l.headset_busy_ms) {
        l.limit = "server: its render + encode per frame (T_remote) exceeds the headset's work";
    } else {
        const double top = std::max({l.decision_ms, l.local_ms, l.uca_ms});
        const char* stage = top == l.local_ms ? "the local render"
                            : top == l.uca_ms ? "UCA"
                                              : "the decision (BVH ring counts)";
        l.limit = fmt::format("headset: busiest stage {}", stage);
    }
    return l;
}

DesignResult designResult(const DesignRun& run, std::optional<ServerBusy> server_busy,
                          const DesignPrediction* prediction, const DesignQuality* quality) {
    DesignResult d;
    d.spec = run.spec;
    d.name = run.label();
    d.summary = run.result.summary;
    d.stats = run.result.stats;
    std::optional<double> served;
    if (server_busy && server_busy->frames > 0)
        served = server_busy->busy_ms_mean;
    d.measured = measuredMetrics(d.summary, served);
    d.speed_before = run.speed_before;
    d.speed_after = run.speed_after;
    if (prediction) {
        d.prediction = *prediction;
        if (prediction->calibrated)
            d.error = predictionError(prediction->calibrated->metrics, d.measured);
        if (prediction->at_probe_speed)
            d.error_at_probe_speed = predictionError(*prediction->at_probe_speed, d.measured);
    }
    d.limits = designLimits(run.result.frames);
    if (quality)
        d.quality = *quality;
    return d;
}

RunOutcome runOutcome(const RunOptions& plan, const HmdProfile& profile,
                      const std::string& scene_name, size_t designs_requested,
                      const CalibrationChoice& calibration, const RunMeasurement& m,
                      const RunPrediction& prediction, DisplayVideo video, double run_seconds) {
    RunOutcome o;
    o.command = plan.command_line;
    o.date = utcNow();
    o.machine = machineDescription();
    o.scene = scene_name;
    o.profile = profile;
    o.net = plan.net;
    o.frames_per_design = plan.frames;
    o.warmup_frames = plan.warmup_frames;
    o.pipeline_depth = plan.pipeline_depth;
    o.quality_every = plan.quality_every;
    o.fovea_border = plan.fovea_border;
    o.interrupted = m.interrupted;
    o.interrupted_note = m.interrupted_note;
    o.designs_requested = designs_requested;
    o.client_core = m.client_core;
    o.server_core = m.server_core;
    o.cores = m.cores;
    o.run_seconds = run_seconds;
    o.headset_share = plan.headset_share;
    if (m.share_group) {
        o.headset_throttling = m.share_group->throttling();
        o.cgroup = m.share_group->path();
    }
    for (size_t i = 0; i < m.runs.size(); ++i) {
        const DesignRun& r = m.runs[i];
        const auto p = prediction.by_design.find(r.label());
        const DesignQuality* q = nullptr;
        for (const auto& [name, dq] : m.quality)
            if (name == r.label())
                q = &dq;
        o.designs.push_back(designResult(
            r, i < m.server_busy.size() ? std::optional(m.server_busy[i]) : std::nullopt,
            p != prediction.by_design.end() ? &p->second : nullptr, q));
    }
    o.calibration = calibration;
    o.workload_source = prediction.workload_source;
    o.bits_frames_own = prediction.bits_frames_own;
    o.speed_note = m.speed_note;
    o.speed = m.speed;
    o.sim_note = prediction.sim_note;
    o.server_stats = m.server_stats;
    o.server_status = m.server_status;
    o.trace = m.trace;
    o.trace_note = m.trace_note;
    o.quality_note = m.quality_note;
    o.video = std::move(video);
    o.headsets = plan.headsets;
    o.identical_workloads = plan.identical_workloads;
    o.headset_offset_ms = plan.headset_offset_ms;
    o.headsets_by_design = m.headsets;
    o.never_shown = m.never_shown;
    o.stale_only = m.stale_only;
    return o;
}

namespace {
double ownLayersFpsOf(const DesignSummary& s) {
    return ownLayersFps(s.fps_mean, s.frames, s.frames_reused);
}
}  // namespace

std::optional<BestFixed> bestFixed(const std::vector<DesignResult>& designs) {
    const DesignResult* best = nullptr;
    for (const DesignResult& d : designs)
        if ((d.spec.design == Design::Fixed || d.spec.design == Design::Ffr) &&
            (!best || beatsForBestFixed(ownLayersFpsOf(d.summary), d.summary.mtp_ms_p99, d.name,
                                        ownLayersFpsOf(best->summary), best->summary.mtp_ms_p99,
                                        best->name)))
            best = &d;
    if (!best)
        return std::nullopt;
    BestFixed bf{best->name,
                 best->spec.fixed_e1_deg,
                 ownLayersFpsOf(best->summary),
                 best->summary.mtp_ms_p99,
                 {}};
    for (const DesignResult& d : designs)
        if (d.spec.design == Design::Qvr || d.spec.design == Design::Sw)
            bf.fps_over_best.emplace_back(d.name, bf.fps_mean > 0.0
                                                      ? ownLayersFpsOf(d.summary) / bf.fps_mean
                                                      : std::numeric_limits<double>::infinity());
    return bf;
}

nlohmann::json bestFixedJson(const BestFixed& bf) {
    nlohmann::json j = {{"design", bf.design},
                        {"e1_deg", bf.e1_deg},
                        {"fps_mean", bf.fps_mean},
                        {"mtp_ms_p99", bf.mtp_ms_p99}};
    // JSON has no infinity: over a fixed design with none of its own frames, "inf" (as qvr sweep).
    for (const auto& [design, ratio] : bf.fps_over_best)
        j[design + "_fps_over_best_fixed"] =
            std::isinf(ratio) ? nlohmann::json("inf") : nlohmann::json(ratio);
    return j;
}

HeadlineRatios headlineRatios(const std::vector<DesignResult>& designs) {
    const DesignSummary* local = nullptr;
    const DesignSummary* remote = nullptr;
    const DesignSummary* qvr = nullptr;
    std::map<std::string, DesignMetrics> paper;  // the paper-hardware model, by design
    for (const DesignResult& d : designs) {
        if (d.spec.design == Design::Local)
            local = &d.summary;
        if (d.spec.design == Design::Remote)
            remote = &d.summary;
        if (d.spec.design == Design::Qvr)
            qvr = &d.summary;
        if (d.prediction.paper_hardware)
            paper[d.name] = *d.prediction.paper_hardware;
    }
    HeadlineRatios r;
    if (qvr && local && local->fps_mean > 0)
        r.qvr_fps_over_local = qvr->fps_mean / local->fps_mean;
    if (qvr && remote && remote->bytes_per_frame_mean > 0)
        r.qvr_bytes_saved_vs_remote =
            1.0 - qvr->bytes_per_frame_mean / remote->bytes_per_frame_mean;
    if (paper.count("qvr") && paper.count("local") && paper["local"].fps_mean > 0)
        r.sim_qvr_fps_over_local = paper["qvr"].fps_mean / paper["local"].fps_mean;
    if (paper.count("qvr") && paper.count("remote") && paper["remote"].bytes_per_frame_mean > 0)
        r.sim_qvr_bytes_saved_vs_remote =
            1.0 - paper["qvr"].bytes_per_frame_mean / paper["remote"].bytes_per_frame_mean;
    return r;
}

namespace {

nlohmann::json optionalJson(const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json();
}

// The metrics a model predicts: the five headline ones, and each side's own cost where the model
// has it.
nlohmann::json predictedJson(const DesignMetrics& m) {
    nlohmann::json j = nlohmann::json::object();
    for (Metric metric : kComparedMetrics) {
        if (const std::optional<double> v = m.value(metric))
            j[metricKey(metric)] = *v;
    }
    return j;
}

nlohmann::json errorPctJson(const PredictionError& e) {
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < kComparedMetrics.size(); ++i)
        j[metricKey(kComparedMetrics[i])] = optionalJson(e.pct[i]);
    return j;
}

// The measured summary and the headset's counters (their shared keys: runtime/session_outputs.h).
nlohmann::json measuredJson(const DesignSummary& s, const HeadsetStats& st) {
    nlohmann::json j = designSummaryJson(s);
    j.update(headsetCountersJson(st));
    j.update({{"t_local_ms_mean", s.t_local_ms_mean},
              {"t_remote_ms_mean", s.t_remote_ms_mean},
              {"uca_ms_mean", s.uca_ms_mean},
              {"wall_s", s.wall_s},
              {"warmup_frames", s.warmup_frames},
              {"startup_mtp_ms_max", s.startup_mtp_ms_max},
              {"startup_unfinished", s.startup_unfinished},
              {"streams_decoded", st.streams_decoded},
              {"decode_failures", st.decode_failures},
              {"key_frame_requests", st.key_frame_requests + st.net.key_frame_requests_sent},
              {"client_core", st.core}});
    return j;
}

nlohmann::json speedJson(const DesignResult& d) {
    nlohmann::json sp = {{"before", nullptr}, {"after", nullptr}};
    for (const auto& [when, p] :
         {std::pair{"before", d.speed_before}, std::pair{"after", d.speed_after}})
        if (p)
            sp[when] = {{"headset_frame_ms", p->headset_ms}, {"server_frame_ms", p->server_ms}};
    if (d.prediction.speed) {
        sp["headset_factor"] = d.prediction.speed->headset;
        sp["server_factor"] = d.prediction.speed->server;
    }
    return sp;
}

nlohmann::json qualityJson(const DesignQuality& q) {
    nlohmann::json d = {{"frames_sampled", q.frames}, {"seconds", q.seconds}};
    for (size_t i = 0; i < DesignQuality::kBands.size(); ++i)
        if (q.counted[i] > 0)
            d[DesignQuality::kBands[i]] = {{"psnr_db", q.psnr_db[i]}, {"ssim", q.ssim[i]}};
    nlohmann::json bins = nlohmann::json::array();
    for (const auto& [deg, sn] : q.psnr_by_ecc)
        bins.push_back({deg, sn.first / sn.second});
    d["psnr_db_by_eccentricity_deg"] = bins;
    return d;
}

nlohmann::json calibrationJson(const RunOutcome& o) {
    const CalibrationChoice& c = o.calibration;
    const RuntimeCosts& costs = c.hardware.runtime;
    nlohmann::json j = {{"source", c.source},
                        {"path", c.path},
                        {"seconds", c.seconds},
                        {"note", c.note},
                        {"bits_frames_own", o.bits_frames_own},
                        {"workload", o.workload_source},
                        {"pipeline_depth", o.pipeline_depth}};
    // The speed reference the per-design probes (designs.<d>.speed) are read against.
    j["speed_reference"] = {
        {"headset_frame_ms", costs.speed_reference_headset_ms},
        {"server_frame_ms", costs.speed_reference_server_ms},
        {"note", o.speed_note.empty()
                     ? std::string("designs.<d>.speed: the probes around each design, their "
                                   "ratio to this reference, and predicted_at_probe_speed: the "
                                   "model with the design's costs at that ratio")
                     : o.speed_note},
        {"run_spread_pct", {{"headset", o.speed.spread_pct[0]}, {"server", o.speed.spread_pct[1]}}},
        {"run_over_reference", o.speed.over_reference[0] > 0.0
                                   ? nlohmann::json{{"headset", o.speed.over_reference[0]},
                                                    {"server", o.speed.over_reference[1]}}
                                   : nlohmann::json()},
        {"unsteady", o.speed.unsteady}};
    return j;
}

// The server's own counters (all designs together), as its process wrote them on exit, and
// its costs per layer and per frame.
nlohmann::json serverJson(const RunOutcome& o) {
    nlohmann::json j = o.server_stats;
    j["exit_status"] = o.server_status;
    const double layers = o.server_stats.value("layers_rendered", 0.0);
    const double frames_rendered = o.server_stats.value("frames_rendered", 0.0);
    if (layers > 0)
        j["encode_ms_per_layer"] = o.server_stats.value("encode_ms_total", 0.0) / layers;
    if (frames_rendered > 0)
        j["render_ms_per_frame"] = o.server_stats.value("render_ms_total", 0.0) / frames_rendered;
    return j;
}

nlohmann::json traceJson(const RunOutcome& o) {
    if (!o.trace)
        return nlohmann::json::object();
    const ChromeTraceInfo& t = *o.trace;
    nlohmann::json j = chromeTraceJson(t);
    j.update({{"frames", t.frames_written},
              {"frames_left_out", t.frames_left_out},
              {"offset_requests", t.offset.requests}});
    return j;
}

// The run's setting: what ran where.
void settingJson(const RunOutcome& o, nlohmann::json& j) {
    j["command"] = o.command;
    j["date"] = o.date;
    j["machine"] = o.machine;
    j["scene"] = o.scene;
    j["profile"] = {{"name", o.profile.name},
                    {"width_px", o.profile.width_px},
                    {"height_px", o.profile.height_px},
                    {"refresh_hz", o.profile.refresh_hz}};
    j["net"] = o.net;
    j["frames_per_design"] = o.frames_per_design;
    j["interrupted"] = o.interrupted;
    if (o.interrupted)
        j["interrupted_note"] = o.interrupted_note;
    j["designs_requested"] = o.designs_requested;
    j["designs_run"] = o.designs.size();
    j["pinning"] = {{"client_core", o.client_core},
                    {"server_core", o.server_core},
                    {"cores", o.cores},
                    {"how",
                     "two processes: the server (qvr server --core N) pins its main thread before "
                     "it creates any other, so all its threads (render, llvmpipe, x264, asio) run "
                     "on its core; the headset thread of this process is pinned to the other core "
                     "and its threads (llvmpipe, x264, asio) inherit the mask"}};
    j["run_seconds"] = o.run_seconds;
    j["headset_share"] = o.headset_share;
    if (o.headset_throttling)
        j["headset_throttling"] = {{"periods", o.headset_throttling->periods},
                                   {"throttled_periods", o.headset_throttling->throttled_periods},
                                   {"throttled_ms", o.headset_throttling->throttled_ms},
                                   {"cgroup", o.cgroup}};
}

}  // namespace

nlohmann::json designJson(const DesignResult& d) {
    nlohmann::json j = measuredJson(d.summary, d.stats);
    j["headset_busy_ms_mean"] = optionalJson(d.measured.headset_busy_ms_mean);
    j["server_busy_ms_mean"] = optionalJson(d.measured.server_busy_ms_mean);
    if (const auto& c = d.prediction.calibrated) {
        j["predicted"] = predictedJson(c->metrics);
        j["predicted"]["t_remote_ms_mean"] = c->t_remote_ms_mean;
        j["predicted"]["frames_reused"] = c->frames_reused;
        j["prediction_error_pct"] = errorPctJson(*d.error);
        j["prediction_error_abs"] = {{"e1_deg_mean", d.error->e1_deg_abs}};
    }
    if (d.prediction.paper_hardware)
        j["predicted_paper_hardware"] = predictedJson(*d.prediction.paper_hardware);
    if (d.prediction.at_probe_speed) {
        j["predicted_at_probe_speed"] = predictedJson(*d.prediction.at_probe_speed);
        j["prediction_error_pct_at_probe_speed"] = errorPctJson(*d.error_at_probe_speed);
        j["prediction_error_abs_at_probe_speed"] = {
            {"e1_deg_mean", d.error_at_probe_speed->e1_deg_abs}};
    }
    j["speed"] = speedJson(d);
    return j;
}

nlohmann::json ratiosJson(const HeadlineRatios& r) {
    nlohmann::json j = nlohmann::json::object();
    if (r.qvr_fps_over_local)
        j["qvr_fps_over_local"] = *r.qvr_fps_over_local;
    if (r.qvr_bytes_saved_vs_remote)
        j["qvr_bytes_saved_vs_remote"] = *r.qvr_bytes_saved_vs_remote;
    j["paper_qvr_fps_over_local"] = HeadlineRatios::kPaperQvrFpsOverLocal;
    j["paper_qvr_bytes_saved_vs_remote"] = HeadlineRatios::kPaperQvrBytesSavedVsRemote;
    if (r.sim_qvr_fps_over_local)
        j["sim_qvr_fps_over_local"] = *r.sim_qvr_fps_over_local;
    if (r.sim_qvr_bytes_saved_vs_remote)
        j["sim_qvr_bytes_saved_vs_remote"] = *r.sim_qvr_bytes_saved_vs_remote;
    return j;
}

namespace {

// With more than one headset: the headsets of the headline design (qvr when run) at the top
// level, every design's besides. One headset's run keeps the keys it always had.
void headsetsSummaryJson(const RunOutcome& o, nlohmann::json& j) {
    if (o.headsets <= 1)
        return;
    j["headsets_requested"] = o.headsets;
    j["identical_workloads"] = o.identical_workloads;
    j["headset_offset_ms"] = o.headset_offset_ms;
    nlohmann::json by_design = nlohmann::json::object();
    for (const HeadsetsResult& r : o.headsets_by_design)
        by_design[r.design] = headsetsJson(r);
    j["headsets_by_design"] = by_design;
    const HeadsetsResult* head = headlineHeadsets(o.headsets_by_design);
    if (!head)
        return;
    const nlohmann::json h = headsetsJson(*head);
    j["headsets_design"] = head->design;
    j["headsets"] = h["headsets"];
    j["jain_fairness_fps"] = h["jain_fairness_fps"];
    j["server_ms_per_headset_frame"] = h["server_ms_per_headset_frame"];
}

}  // namespace

nlohmann::json summaryJson(const RunOutcome& o) {
    nlohmann::json j;
    settingJson(o, j);
    nlohmann::json designs = nlohmann::json::object();
    nlohmann::json sim = nlohmann::json::object();  // the paper-hardware model, by design
    nlohmann::json quality = nlohmann::json::object();
    for (const DesignResult& d : o.designs) {
        designs[d.name] = designJson(d);
        if (d.prediction.paper_hardware)
            sim[d.name] = predictedJson(*d.prediction.paper_hardware);
        if (d.quality)
            quality[d.name] = qualityJson(*d.quality);
    }
    j["designs"] = designs;
    if (const auto bf = bestFixed(o.designs))
        j["best_fixed"] = bestFixedJson(*bf);
    j["ratios"] = ratiosJson(headlineRatios(o.designs));
    j["sim_prediction"] = sim;
    j["calibration"] = calibrationJson(o);
    if (!o.sim_note.empty())
        j["sim_note"] = o.sim_note;
    j["server"] = serverJson(o);
    j["trace"] = traceJson(o);
    headsetsSummaryJson(o, j);
    if (!o.quality_note.empty())
        quality["note"] = o.quality_note;
    j["quality"] = quality;
    if (const auto& v = o.video.info)
        j["video"] = {{"path", "qvr_display.mp4"},
                      {"container", v->format_name},
                      {"codec", v->codec_name},
                      {"profile", v->profile},
                      {"width_px", v->width},
                      {"height_px", v->height},
                      {"fps", v->fps},
                      {"frames", v->frames}};
    return j;
}

}  // namespace qvr::experiment
