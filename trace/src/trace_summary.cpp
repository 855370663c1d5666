#include "qvr/trace/trace_summary.h"

#include <algorithm>

#include <fmt/format.h>

namespace qvr {

HeadTurnStats headTurnStats(const PoseTrace& trace, double rate_hz) {
    const auto& s = trace.samples;
    HeadTurnStats stats;
    double sum_deg_s = 0.0;
    for (size_t i = 1; i < s.size(); ++i) {
        const double v =
            angleBetweenDeg(s[i - 1].pose.orientation, s[i].pose.orientation) * rate_hz;
        sum_deg_s += v;
        stats.max_deg_s = std::max(stats.max_deg_s, v);
    }
    if (s.size() > 1)
        stats.mean_deg_s = sum_deg_s / static_cast<double>(s.size() - 1);
    return stats;
}

std::string headTraceReport(const std::string& bvh_path, const BvhMotion& motion,
                            const HeadMotionOptions& options, const PoseTrace& trace,
                            const std::string& out_path) {
    const BvhUnit used = options.unit == BvhUnit::kAuto ? detectBvhUnit(motion) : options.unit;
    auto head = findHeadJoint(motion, options.head_joint);
    const std::string head_name = head ? motion.joints[static_cast<size_t>(*head)].name : "";
    const auto& s = trace.samples;
    const HeadTurnStats turn = headTurnStats(trace, options.rate_hz);
    return fmt::format(
        "{}: {} frames at {:.4g} Hz, {} joints, unit {} ({:.5f} m), head joint '{}'\n"
        "wrote {}: {} poses at {} Hz ({:.2f} s), head turn mean {:.1f} deg/s, max "
        "{:.1f} deg/s\n",
        bvh_path, motion.frame_count, 1.0 / motion.frame_time_s, motion.joints.size(),
        bvhUnitName(used), bvhUnitMetres(used), head_name, out_path, s.size(), options.rate_hz,
        s.empty() ? 0.0 : s.back().t_ms / 1000.0, turn.mean_deg_s, turn.max_deg_s);
}

GazeEventCounts countGazeEvents(const GazeTrace& trace) {
    GazeEventCounts counts;
    double amplitude_sum = 0.0;
    for (const auto& e : trace.events) {
        switch (e.kind) {
            case GazeEventKind::kFixation:
                ++counts.fixations;
                break;
            case GazeEventKind::kPursuit:
                ++counts.pursuits;
                break;
            case GazeEventKind::kSaccade:
                ++counts.saccades;
                amplitude_sum += e.amplitude_deg;
                break;
        }
    }
    if (counts.saccades > 0)
        counts.mean_saccade_deg = amplitude_sum / counts.saccades;
    return counts;
}

std::string gazeTraceReport(const GazeTrace& trace, const GazeModelConfig& model, uint64_t seed,
                            const std::string& out_path) {
    const GazeEventCounts c = countGazeEvents(trace);
    return fmt::format(
        "wrote {}: {} samples at {} Hz ({:.2f} s), seed {}: {} fixations, {} pursuits, "
        "{} saccades (mean amplitude {:.1f} deg)\n",
        out_path, trace.samples.size(), model.sample_rate_hz,
        trace.samples.empty() ? 0.0 : trace.samples.back().t_ms / 1000.0, seed, c.fixations,
        c.pursuits, c.saccades, c.mean_saccade_deg);
}

}  // namespace qvr
