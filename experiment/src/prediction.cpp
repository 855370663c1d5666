#include "qvr/experiment/prediction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <tuple>
#include <variant>

#include <fmt/format.h>

#include "qvr/core/enum_table.h"
#include "qvr/render/camera.h"
#include "qvr/render/draw_list.h"
#include "qvr/render/renderer.h"
#include "qvr/runtime/cpu_share.h"
#include "qvr/runtime/workload_probe.h"
#include "qvr/sim/capacity.h"
#include "qvr/sim/network.h"
#include "qvr/sim/simulator.h"
#include "qvr/workload/trace_io.h"

namespace qvr::experiment {

namespace fs = std::filesystem;
using runtime::DesignSummary;
using runtime::FrameTelemetry;

namespace {

// Each compared metric's key in summary.json and the DesignMetrics member that holds it.
struct MetricRow {
    using Member = std::variant<double DesignMetrics::*, std::optional<double> DesignMetrics::*>;
    Metric value;
    const char* name;
    Member member;
};

constexpr MetricRow kMetrics[] = {
    {Metric::kFps, "fps_mean", &DesignMetrics::fps_mean},
    {Metric::kMtpMean, "mtp_ms_mean", &DesignMetrics::mtp_ms_mean},
    {Metric::kMtpP99, "mtp_ms_p99", &DesignMetrics::mtp_ms_p99},
    {Metric::kBytes, "bytes_per_frame_mean", &DesignMetrics::bytes_per_frame_mean},
    {Metric::kE1, "e1_deg_mean", &DesignMetrics::e1_deg_mean},
    {Metric::kHeadsetBusy, "headset_busy_ms_mean", &DesignMetrics::headset_busy_ms_mean},
    {Metric::kServerBusy, "server_busy_ms_mean", &DesignMetrics::server_busy_ms_mean}};

}  // namespace

const char* metricKey(Metric metric) {
    return enumName(kMetrics, metric, "");
}

std::optional<double> DesignMetrics::value(Metric metric) const {
    const MetricRow* row = enumRow(kMetrics, metric);
    if (row == nullptr)
        return std::nullopt;
    return std::visit([this](auto member) -> std::optional<double> { return this->*member; },
                      row->member);
}

DesignMetrics measuredMetrics(const DesignSummary& s, std::optional<double> server_busy_ms_mean) {
    DesignMetrics m{s.fps_mean,    s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean,
                    s.e1_deg_mean, std::nullopt,  std::nullopt};
    if (s.headset_busy_frames > 0)
        m.headset_busy_ms_mean = s.headset_busy_ms_mean;
    m.server_busy_ms_mean = server_busy_ms_mean;
    return m;
}

std::optional<double> PredictionError::pctOf(Metric metric) const {
    for (size_t i = 0; i < kComparedMetrics.size(); ++i)
        if (kComparedMetrics[i] == metric)
            return pct[i];
    return std::nullopt;
}

PredictionError predictionError(const DesignMetrics& predicted, const DesignMetrics& measured) {
    PredictionError e;
    for (size_t i = 0; i < kComparedMetrics.size(); ++i) {
        const double m = measured.value(kComparedMetrics[i]).value_or(0.0);
        const std::optional<double> p = predicted.value(kComparedMetrics[i]);
        if (m != 0.0 && p)
            e.pct[i] = 100.0 * (*p - m) / std::fabs(m);
    }
    e.e1_deg_abs = predicted.e1_deg_mean - measured.e1_deg_mean;
    return e;
}

std::optional<SideFactors> speedFactors(const DesignRun& run, const RuntimeCosts& calibrated) {
    double h = 0.0, sv = 0.0;
    int n = 0;
    for (const std::optional<SpeedSample>& p : {run.speed_before, run.speed_after})
        if (p) {
            h += p->headset_ms;
            sv += p->server_ms;
            ++n;
        }
    if (n == 0 || calibrated.speed_reference_headset_ms <= 0.0 ||
        calibrated.speed_reference_server_ms <= 0.0)
        return std::nullopt;
    return SideFactors{h / n / calibrated.speed_reference_headset_ms,
                       sv / n / calibrated.speed_reference_server_ms};
}

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

ModelSettings modelSettings(const RunOptions& plan) {
    ModelSettings s;
    s.net = plan.net;
    s.seed = plan.seed;
    s.pipeline_depth = plan.pipeline_depth;
    s.remote_timeout_ms = plan.remote_timeout_ms;
    s.warmup_frames = plan.warmup_frames;  // the same frames left out as measured
    s.record_scanout = plan.video;         // every design's headset copies its scan-out
    s.headset_share = plan.headset_share;
    s.headsets = plan.headsets;
    return s;
}

namespace {

// `server_factor`: the model ran the server N times slower for N headsets; its time per
// headset-frame, what the run measures, is 1/N of the modelled frame's.
DesignMetrics metricsOf(const RuntimeSummary& s, double server_factor = 1.0) {
    return {s.fps_mean,
            s.mtp_ms_mean,
            s.mtp_ms_p99,
            s.bytes_per_frame_mean,
            s.e1_deg_mean,
            s.headset_busy_ms_mean,
            s.server_busy_ms_mean / server_factor};
}

// One headset's share is modelled as its CFS quota (RuntimeSimConfig::headset_share); several
// headsets share the headset's core by the capacity model's speed factors (capacityFactors).
bool shareIsAQuota(const ModelSettings& settings) {
    return settings.headsets <= 1;
}

// One pass of the calibrated runtime model with `costs` on the run's link (none: the model
// cannot make that link).
std::optional<RuntimeRunResult> runModel(const WorkloadTrace& trace, Design design,
                                         double fixed_e1_deg, RuntimeCosts costs,
                                         const ModelSettings& settings,
                                         const DesignModelInputs& inputs) {
    double delay_ms = 0.0;
    auto link = makeRuntimeLink(settings.net, &delay_ms);
    if (!link)
        return std::nullopt;
    RuntimeSimConfig rc;
    rc.design = design;
    rc.fixed_e1_deg = fixed_e1_deg;
    rc.costs = std::move(costs);
    rc.costs.link_delay_ms += delay_ms;
    rc.pipeline_depth = settings.pipeline_depth;
    rc.wait_limit_ms = settings.remote_timeout_ms;
    rc.frames = static_cast<int>(trace.frames.size());
    rc.warmup_frames = settings.warmup_frames;
    rc.record_scanout = settings.record_scanout;
    if (shareIsAQuota(settings)) {
        rc.headset_share = settings.headset_share;
        rc.quota_period_ms = runtime::CpuShareGroup::kDefaultPeriodUs * 1e-3;
    }
    // The trace's frame k is the run's frame k (same poses).
    rc.layer_triangles = inputs.layer_triangles;
    rc.fovea_fragments = inputs.fovea_fragments;
    rc.server_fragments = inputs.server_fragments;
    return simulateRuntime(trace, rc, **link);
}

}  // namespace

DesignPrediction predictDesign(const WorkloadTrace& trace, const DesignModelInputs& inputs,
                               const RuntimeCosts& calibrated, const ModelSettings& settings,
                               const std::optional<NetworkSpec>& paper_net,
                               std::vector<RuntimeFrame>* frames) {
    DesignPrediction p;
    Design sd = Design::Qvr;
    double fixed_e1 = 5.0;
    if (!simDesignOf(inputs.design, sd, fixed_e1))
        return p;
    p.speed = inputs.speed;
    // One headset's share is throttled in runModel as CFS does (docs/MODEL.md §13); N headsets
    // on one server each get 1/N of its time and share the headset's core (capacityFactors).
    const SideFactors f = capacityFactors(
        settings.headsets, shareIsAQuota(settings) ? 1.0 : settings.headset_share, true);
    const RuntimeCosts costs =
        f.headset != 1.0 || f.server != 1.0 ? calibrated.atSpeed(f.headset, f.server) : calibrated;
    if (auto r = runModel(trace, sd, fixed_e1, costs, settings, inputs)) {
        p.calibrated = RuntimePrediction{metricsOf(r->summary, f.server),
                                         r->summary.t_remote_ms_mean, r->summary.frames_reused};
        if (frames)
            *frames = std::move(r->frames);
        // With probes: the same model with the costs at the probes' speed, beside it.
        if (inputs.speed)
            if (auto at = runModel(trace, sd, fixed_e1,
                                   costs.atSpeed(inputs.speed->headset, inputs.speed->server),
                                   settings, inputs))
                p.at_probe_speed = metricsOf(at->summary, f.server);
    }
    if (paper_net) {
        auto sim_link = makeLink(*paper_net, settings.seed);
        if (!sim_link)
            return p;
        SimConfig cfg;
        cfg.bench = "qvr-run";
        cfg.design = sd;
        cfg.frames = static_cast<int>(trace.frames.size());
        const RunSummary s = simulate(trace, cfg, **sim_link).summary;
        p.paper_hardware =
            DesignMetrics{s.fps_mean,    s.mtp_ms_mean, s.mtp_ms_p99, s.bytes_per_frame_mean,
                          s.e1_deg_mean, std::nullopt,  std::nullopt};
    }
    return p;
}

LayerTrianglesFn drawnLayerTriangles(std::shared_ptr<const DrawList> draw_list,
                                     const HmdProfile& profile, float lod_px, bool holes,
                                     std::function<Pose(int64_t frame)> head_pose_at) {
    // By (frame, e1 in 1/1000°, eye, kind): LIWC revisits the same candidates.
    auto cache = std::make_shared<std::map<std::tuple<int64_t, int64_t, int, int>, double>>();
    const LayerHoles server_holes{.enabled = holes};
    return [=](int64_t frame, const LayerPlan& layer_plan, int eye, int kind) {
        const auto key = std::make_tuple(
            frame, static_cast<int64_t>(std::llround(layer_plan.e1_deg * 1000.0)), eye, kind);
        if (auto it = cache->find(key); it != cache->end())
            return it->second;
        const LayerKind lk = kind == 0   ? LayerKind::kFovea
                             : kind == 1 ? LayerKind::kMiddle
                                         : LayerKind::kOuter;
        const double tris = double(layerTriangles(
            *draw_list, profile, layer_plan, head_pose_at(frame), static_cast<Eye>(eye), lk, lod_px,
            CameraOptions{}, lk == LayerKind::kFovea ? LayerHoles{} : server_holes));
        cache->emplace(key, tris);
        return tris;
    };
}

namespace {

// The layers' triangles for the run's poses and the plan the model chose.
LayerTrianglesFn makeLayerTriangles(const RunOptions& plan, const HmdProfile& profile,
                                    const runtime::HeadsetInputs& inputs,
                                    std::shared_ptr<const DrawList> draw_list) {
    const PoseTrace* motion = &inputs.traces.motion;
    const double refresh_hz = profile.refresh_hz;
    return drawnLayerTriangles(std::move(draw_list), profile, plan.lod_px, !plan.no_holes,
                               [motion, refresh_hz](int64_t frame) {
                                   return poseAt(*motion, contentTimeMs(frame, refresh_hz));
                               });
}

// The fragments a design's fovea pass shaded at frame k, as its own run's headset counted them
// (FrameTelemetry::fovea_fragments, both eyes): the overdraw the fovea law charges (docs/
// MODEL.md §9). A count of the content at that pose and e1, as the triangles are,
// not a time. Where the model's e1 differs from the run's (LIWC's choices), the run's fragments
// per fovea pixel times the model's pixels; none counted: −1, the law's mean.
FoveaFragmentsFn foveaFragmentsOf(const DesignRun& run, const HmdProfile& profile,
                                  const runtime::HeadsetTraces& traces) {
    std::vector<std::pair<double, double>> by_frame;  // e1, fragments per eye
    for (const FrameTelemetry& t : run.result.frames) {
        if (t.frame < 0 || t.frame > 1000000)
            continue;
        if (by_frame.size() <= size_t(t.frame))
            by_frame.resize(size_t(t.frame) + 1, {0.0, -1.0});
        by_frame[size_t(t.frame)] = {t.e1_deg,
                                     t.fovea_fragments > 0.0 ? t.fovea_fragments / 2.0 : -1.0};
    }
    auto planner = std::make_shared<const LayerPlanner>(profile);
    const GazeTrace* gaze = &traces.gaze;
    const double refresh_hz = profile.refresh_hz;
    return [=](int64_t frame, const LayerPlan& plan, int eye) -> double {
        if (frame < 0 || size_t(frame) >= by_frame.size() || by_frame[size_t(frame)].second < 0)
            return -1.0;
        const auto [e1, frags] = by_frame[size_t(frame)];
        const LayerRect& model = plan.eyes[size_t(eye)].fovea;
        if (std::fabs(plan.e1_deg - e1) < 1e-3 || model.empty())
            return frags;
        const double content_ms = contentTimeMs(frame, refresh_hz);
        const LayerPlan run_plan = planner->plan(gazeAt(*gaze, content_ms), e1);
        const double run_px = double(run_plan.eyes[size_t(eye)].fovea.pixels());
        return run_px > 0.0 ? frags * double(model.pixels()) / run_px : -1.0;
    };
}

}  // namespace

ServerFragmentsFn serverFragmentsOf(const std::vector<std::array<double, 4>>& fragments_per_px) {
    const size_t n = fragments_per_px.size();
    // Per stream and frame, the nearest counted frame's fragments per pixel (−1: none counted).
    std::array<std::vector<double>, 4> nearest;
    bool any = false;
    for (size_t s = 0; s < 4; ++s) {
        std::vector<double>& v = nearest[s];
        v.assign(n, -1.0);
        std::vector<size_t> distance(n, std::numeric_limits<size_t>::max());
        for (size_t k = 0, last = n; k < n; ++k) {  // the nearest counted frame at or before k
            if (fragments_per_px[k][s] >= 0.0)
                last = k;
            if (last < n)
                std::tie(v[k], distance[k]) = std::pair(fragments_per_px[last][s], k - last);
        }
        for (size_t k = n, next = n; k-- > 0;) {  // or after it, when nearer
            if (fragments_per_px[k][s] >= 0.0)
                next = k;
            if (next < n && next - k < distance[k])
                v[k] = fragments_per_px[next][s];
        }
        any = any || (n > 0 && v[0] >= 0.0);
    }
    if (!any)
        return {};
    return [nearest](int64_t frame, int stream, double pixels) -> double {
        if (stream < 0 || stream >= 4 || nearest[size_t(stream)].empty())
            return -1.0;
        const std::vector<double>& v = nearest[size_t(stream)];
        const double per_px = v[size_t(std::clamp<int64_t>(frame, 0, int64_t(v.size()) - 1))];
        return per_px >= 0.0 ? per_px * pixels : -1.0;
    };
}

namespace {

struct PredictionWorkload {
    Expected<WorkloadTrace> trace = makeError("no workload");
    std::string source;
    size_t bits_frames_own = 0;
};

// The workload the predictions replay: every frame's triangles and pixels per ring as the
// headset's LIWC counts them (the draw clusters at the fovea's level of detail, or the BVH with
// --ring-counts bvh; all rings), computed after the runs, off the clock, for the same poses and
// gazes; bits per pixel from the calibration's codec law. So every design set gets a prediction
// and nothing in it is measured on the run. Without a bits law in the calibration, the qvr
// design's recorded workload (its bits per pixel as the headset estimated them).
PredictionWorkload predictionWorkload(const RunOptions& plan, const HmdProfile& profile,
                                      const runtime::HeadsetInputs& inputs,
                                      const RuntimeCosts& costs, const RunMeasurement& m,
                                      std::shared_ptr<const DrawList> draw_list) {
    PredictionWorkload w;
    if (costs.bits_per_px_at_1 <= 0.0) {
        if (m.recorded_workload) {
            w.trace = loadWorkloadTrace((fs::path(plan.out) / "workload.jsonl").string());
            w.source = "workload.jsonl recorded by the qvr design";
        }
        return w;
    }
    const auto t0 = std::chrono::steady_clock::now();
    runtime::WorkloadProbe probe(profile, inputs.bvh);
    if (plan.ring_counts == "clusters")
        probe.useClusters(draw_list, plan.lod_px);
    probe.setName("qvr-run-prediction", "qvr run: the run's poses and gazes, LIWC's rings");
    WorkloadTrace t;
    t.header = probe.header();
    // An interrupted run predicts the frames its designs got through, not the ones asked for.
    size_t predict_frames = static_cast<size_t>(plan.frames);
    if (m.interrupted) {
        predict_frames = 0;
        for (const DesignRun& r : m.runs)
            predict_frames = std::max(predict_frames, r.result.frames.size());
    }
    for (size_t i = 0; i < predict_frames; ++i) {
        const double content_ms = contentTimeMs(static_cast<int64_t>(i), profile.refresh_hz);
        WorkloadFrame wf = probe.frame(static_cast<int64_t>(i), content_ms,
                                       poseAt(inputs.traces.motion, content_ms),
                                       gazeAt(inputs.traces.gaze, content_ms), 180.0);
        for (size_t k = 0; k < wf.bits_per_pixel.size(); ++k)
            wf.bits_per_pixel[k] =
                costs.bits_per_px_at_1 * std::pow(t.header.scales[k], costs.bits_scale_exponent);
        // The calibration coded this very head pose as its frame i: the frame's own bits.
        if (costs.bitsFrameMeasured(i, frameContentKey(wf.head)))
            ++w.bits_frames_own;
        t.frames.push_back(std::move(wf));
    }
    w.trace = std::move(t);
    w.source = fmt::format(
        "the run's poses and gazes, {} ring counts computed after the run ({:.1f} s), bits "
        "per pixel from the calibration ({} of {} frames their own, coded by the calibration "
        "on the same head pose; the rest its law); layer triangles drawn (LOD, holes) counted "
        "off the clock; the fovea's shaded fragments as each design's own passes counted them "
        "(a count, not a time: its overdraw, docs/MODEL.md §9)",
        plan.ring_counts,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
        w.bits_frames_own, predict_frames);
    return w;
}

// The model's frames beside telemetry.csv's, to chase an error to its stage.
constexpr const char* kPredictedFramesHeader =
    "design,frame,e1_deg,pose_ms,t_local_ms,t_remote_ms,headset_busy_ms,decision_ms,"
    "remote_done_ms,uca_end_ms,display_ms,mtp_ms,uca_ms,bytes,reused,served,server_render_ms,"
    "server_encode_ms,key_frames\n";

void writePredictedFrames(std::ostream& csv, const std::string& name,
                          const std::vector<RuntimeFrame>& frames) {
    for (const RuntimeFrame& f : frames)
        csv << fmt::format(
            "{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},"
            "{:.0f},{:d},{:d},{:.3f},{:.3f},{:d}\n",
            name, f.index, f.e1_deg, f.pose_ms, f.t_local_ms, f.t_remote_ms, f.headset_busy_ms,
            f.decision_ms, f.remote_done_ms, f.uca_end_ms, f.display_ms, f.mtp_ms,
            f.uca_end_ms - f.uca_start_ms, f.bytes, int(f.reused), int(f.served),
            f.server_render_ms, f.server_encode_ms, f.key_frames);
}

// The paper model's network for the run's link, and what the report says about both links.
std::optional<NetworkSpec> paperNetwork(const std::string& net, std::string& sim_note) {
    const std::string net_name = net.substr(0, net.find(','));
    auto spec = networkSpecByName(net_name);
    if (!spec) {
        sim_note = fmt::format(
            "--net '{}' has no paper-model profile; the paper-hardware column uses wifi", net_name);
        spec = networkSpecByName("wifi");
    }
    double delay_ms = 0.0;
    if (auto link = makeRuntimeLink(net, &delay_ms); !link)
        sim_note += (sim_note.empty() ? "" : "; ") + ("no calibrated prediction: " + link.error());
    return spec ? std::optional<NetworkSpec>(*spec) : std::nullopt;
}

}  // namespace

RunPrediction predictRun(const RunOptions& plan, const HmdProfile& profile,
                         const runtime::HeadsetInputs& inputs, const RuntimeCosts& calibrated,
                         const RunMeasurement& measurement) {
    RunPrediction rp;
    auto draw_list = std::make_shared<DrawList>(buildDrawList(*inputs.scene));
    if (plan.lod_px > 0.0f)
        buildLods(*draw_list, *inputs.scene);
    PredictionWorkload w =
        predictionWorkload(plan, profile, inputs, calibrated, measurement, draw_list);
    rp.workload_source = w.source;
    rp.bits_frames_own = w.bits_frames_own;
    if (!w.trace) {
        rp.sim_note =
            "no prediction: the workload is recorded during the qvr design's run, and "
            "--designs has no qvr";
        return rp;
    }
    const std::optional<NetworkSpec> paper_net = paperNetwork(plan.net, rp.sim_note);
    std::ofstream predicted_csv(fs::path(plan.out) / "predicted_frames.csv");
    predicted_csv << kPredictedFramesHeader;
    if (w.trace->frames.empty())
        return rp;
    const ModelSettings settings = modelSettings(plan);
    const LayerTrianglesFn layer_triangles = makeLayerTriangles(plan, profile, inputs, draw_list);
    for (size_t i = 0; i < measurement.runs.size(); ++i) {
        const DesignRun& r = measurement.runs[i];
        const DesignModelInputs di{
            r.label(), speedFactors(r, calibrated), layer_triangles,
            foveaFragmentsOf(r, profile, inputs.traces),
            i < measurement.server_busy.size()
                ? serverFragmentsOf(measurement.server_busy[i].fragments_per_px)
                : ServerFragmentsFn{}};
        std::vector<RuntimeFrame> frames;
        DesignPrediction p = predictDesign(*w.trace, di, calibrated, settings, paper_net, &frames);
        writePredictedFrames(predicted_csv, di.design, frames);
        rp.by_design[di.design] = std::move(p);
    }
    if (plan.headset_share < 1.0 && measurement.share_group) {
        const auto t = measurement.share_group->throttling();
        rp.sim_note += fmt::format(
            "{}the model throttled the headset as its quota does ({:g} of every {} ms, "
            "--headset-share); the quota throttled {} of {} periods (docs/MODEL.md §13)",
            rp.sim_note.empty() ? "" : "; ", plan.headset_share,
            runtime::CpuShareGroup::kDefaultPeriodUs / 1000, t.throttled_periods, t.periods);
    }
    return rp;
}

}  // namespace qvr::experiment
