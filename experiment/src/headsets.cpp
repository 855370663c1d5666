// Several headsets on one render server: workloads, fairness and the server's share (headsets.h).
#include "qvr/experiment/headsets.h"

#include <algorithm>

namespace qvr::experiment {

std::vector<std::string> defaultMotionRecordings() {
    return {"/usr/share/assimp/models/BVH/01_01.bvh", "/usr/share/assimp/models/BVH/01_03.bvh",
            "/usr/share/assimp/models/BVH/Boxing_Toes.bvh"};
}

std::vector<HeadsetWorkload> headsetWorkloads(int headsets, const std::string& motion,
                                              const std::string& gaze, uint64_t seed,
                                              bool identical,
                                              const std::vector<std::string>& recordings,
                                              double offset_ms) {
    std::vector<HeadsetWorkload> out;
    for (int k = 0; k < headsets; ++k) {
        HeadsetWorkload w{motion, gaze, seed, double(k) * offset_ms};
        if (k > 0 && !identical) {
            w.seed = seed + uint64_t(k);
            if (motion == "default" && !recordings.empty())
                w.motion = recordings[size_t(k) % recordings.size()];
        }
        out.push_back(w);
    }
    return out;
}

double jainFairness(std::span<const double> values) {
    double sum = 0.0, sum_sq = 0.0;
    for (double v : values) {
        const double x = std::max(v, 0.0);
        sum += x;
        sum_sq += x * x;
    }
    if (values.empty() || sum_sq <= 0.0)
        return 1.0;
    return sum * sum / (double(values.size()) * sum_sq);
}

ServerShare serverShare(const std::vector<runtime::ServerFrameStamps>& stamps, int64_t start_ns,
                        int64_t end_ns) {
    ServerShare share;
    for (const runtime::ServerFrameStamps& s : stamps) {
        if (s.start_ns < start_ns || s.start_ns > end_ns)
            continue;
        ++share.frames;
        for (const runtime::ServerFrameStamps::Layer& l : s.layers)
            share.busy_ms_total +=
                double(std::max<int64_t>(0, l.encode_end_ns - l.render_start_ns)) * 1e-6;
    }
    return share;
}

HeadsetsResult aggregateHeadsets(const std::string& design, std::vector<HeadsetOutcome> headsets,
                                 const std::optional<ServerShare>& server) {
    HeadsetsResult r;
    r.design = design;
    std::sort(headsets.begin(), headsets.end(),
              [](const HeadsetOutcome& a, const HeadsetOutcome& b) { return a.index < b.index; });
    r.headsets = std::move(headsets);
    std::vector<double> fps;
    for (const HeadsetOutcome& h : r.headsets)
        if (h.error.empty())
            fps.push_back(h.summary.fps_mean);
    r.jain_fairness_fps = jainFairness(fps);
    if (!fps.empty()) {
        double sum = 0.0;
        for (double f : fps)
            sum += f;
        r.fps_mean = sum / double(fps.size());
        r.fps_min = *std::min_element(fps.begin(), fps.end());
    }
    if (server && server->frames > 0)
        r.server_ms_per_headset_frame = server->msPerFrame();
    return r;
}

nlohmann::json headsetJson(const HeadsetOutcome& h) {
    nlohmann::json j = {{"headset", h.index},
                        {"motion", h.workload.motion},
                        {"gaze", h.workload.gaze},
                        {"seed", h.workload.seed},
                        {"ahead_ms", h.workload.ahead_ms}};
    if (!h.error.empty()) {
        j["error"] = h.error;
        return j;
    }
    const runtime::DesignSummary& s = h.summary;
    j["frames"] = s.frames;
    j["fps_mean"] = s.fps_mean;
    j["mtp_ms_mean"] = s.mtp_ms_mean;
    j["mtp_ms_p99"] = s.mtp_ms_p99;
    j["bytes_per_frame_mean"] = s.bytes_per_frame_mean;
    j["e1_deg_mean"] = s.e1_deg_mean;
    j["frames_displayed"] = s.frames_displayed;
    j["frames_reused"] = s.frames_reused;
    return j;
}

nlohmann::json headsetsJson(const HeadsetsResult& r) {
    nlohmann::json list = nlohmann::json::array();
    for (const HeadsetOutcome& h : r.headsets)
        list.push_back(headsetJson(h));
    nlohmann::json j = {{"design", r.design},
                        {"headsets", list},
                        {"jain_fairness_fps", r.jain_fairness_fps},
                        {"fps_mean", r.fps_mean},
                        {"fps_min", r.fps_min}};
    j["server_ms_per_headset_frame"] = r.server_ms_per_headset_frame
                                           ? nlohmann::json(*r.server_ms_per_headset_frame)
                                           : nlohmann::json(nullptr);
    return j;
}

const HeadsetsResult* headlineHeadsets(const std::vector<HeadsetsResult>& by_design) {
    for (const HeadsetsResult& r : by_design)
        if (r.design == "qvr")
            return &r;
    return by_design.empty() ? nullptr : &by_design.back();
}

}  // namespace qvr::experiment
