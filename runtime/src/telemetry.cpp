// Telemetry: CSV rows and the per-design summary `qvr run` writes.
#include "qvr/runtime/telemetry.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include <fmt/format.h>

namespace qvr::runtime {

double percentile(std::vector<double> values, double p) {
    if (values.empty())
        return 0.0;
    std::sort(values.begin(), values.end());
    const double rank = std::ceil(p / 100.0 * static_cast<double>(values.size()));
    const size_t idx = static_cast<size_t>(std::clamp(rank, 1.0, double(values.size()))) - 1;
    return values[idx];
}

DesignSummary summarizeRun(const std::string& design, const std::vector<FrameTelemetry>& all,
                           int warmup_frames) {
    DesignSummary s;
    s.design = design;
    const size_t skip = warmup_frames > 0 && all.size() > static_cast<size_t>(warmup_frames)
                            ? static_cast<size_t>(warmup_frames)
                            : 0;
    s.warmup_frames = static_cast<int>(skip);
    for (size_t k = 0; k < skip; ++k)
        s.startup_mtp_ms_max = std::max(s.startup_mtp_ms_max, all[k].mtp_ms);
    const std::vector<FrameTelemetry> frames(all.begin() + static_cast<std::ptrdiff_t>(skip),
                                             all.end());
    s.frames = static_cast<int>(frames.size());
    std::vector<double> mtp;
    double bytes = 0, e1 = 0, t_local = 0, t_remote = 0, uca = 0;
    int remote_frames = 0;
    int64_t first_display = -1, last_display = -1;
    for (const FrameTelemetry& t : frames) {
        if (t.display_ns >= 0) {
            ++s.frames_displayed;
            if (first_display < 0)
                first_display = t.display_ns;
            last_display = t.display_ns;
        }
        if (t.reused)
            ++s.frames_reused;
        if (t.fallback_local)
            s.frames_fallback_local += 1;
        mtp.push_back(t.mtp_ms);
        bytes += static_cast<double>(t.bytes);
        e1 += t.e1_deg;
        t_local += t.t_local_ms;
        uca += t.uca_ms;
        if (t.remote_requested) {
            t_remote += t.t_remote_ms;
            ++remote_frames;
        }
    }
    if (!frames.empty()) {
        const double n = static_cast<double>(frames.size());
        s.mtp_ms_mean = std::accumulate(mtp.begin(), mtp.end(), 0.0) / n;
        s.mtp_ms_p99 = percentile(mtp, 99.0);
        s.bytes_per_frame_mean = bytes / n;
        s.e1_deg_mean = e1 / n;
        s.t_local_ms_mean = t_local / n;
        s.uca_ms_mean = uca / n;
        s.wall_s = static_cast<double>(frames.back().display_ns - frames.front().pose_ns) * 1e-9;
    }
    if (remote_frames > 0)
        s.t_remote_ms_mean = t_remote / remote_frames;
    // Frames per second of scan-out: displays over the time between the first and the last,
    // so start-up does not count.
    if (s.frames_displayed > 1 && last_display > first_display)
        s.fps_mean = static_cast<double>(s.frames_displayed - 1) * 1e9 /
                     static_cast<double>(last_display - first_display);
    return s;
}

std::string telemetryCsvHeader() {
    std::string h =
        "design,frame,e1_deg,e2_deg,pose_ns,decision_ns,local_start_ns,local_end_ns,request_ns";
    for (int s = 0; s < kStreams; ++s)
        h += fmt::format(",stream{}_rx_ns,stream{}_decoded_ns", s, s);
    h += ",remote_done_ns,uca_start_ns,uca_end_ns,display_ns,bytes,remote_requested,reused,"
         "shown_frame,connected,fallback_local,t_local_ms,t_remote_ms,uca_ms,mtp_ms,"
         "throughput_bps,fovea_triangles,warp_deg,headset_busy_ms,t_remote_decoded_ms,"
         "t_local_pred_ms,t_remote_pred_ms,probe_ms\n";
    return h;
}

std::string telemetryCsvRow(const std::string& design, const FrameTelemetry& t) {
    std::string r =
        fmt::format("{},{},{:.3f},{:.3f},{},{},{},{},{}", design, t.frame, t.e1_deg, t.e2_deg,
                    t.pose_ns, t.decision_ns, t.local_start_ns, t.local_end_ns, t.request_ns);
    for (int s = 0; s < kStreams; ++s)
        r += fmt::format(",{},{}", t.stream_rx_ns[static_cast<size_t>(s)],
                         t.stream_decoded_ns[static_cast<size_t>(s)]);
    r += fmt::format(
        ",{},{},{},{},{},{},{},{},{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.0f},{:.0f},{:.3f},{:.3f},"
        "{:.3f},{:.3f},{:.3f},{:.3f}\n",
        t.remote_done_ns, t.uca_start_ns, t.uca_end_ns, t.display_ns, t.bytes,
        int(t.remote_requested), int(t.reused), t.shown_frame, int(t.connected),
        int(t.fallback_local), t.t_local_ms, t.t_remote_ms, t.uca_ms, t.mtp_ms, t.throughput_bps,
        t.fovea_triangles, t.warp_deg, t.headset_busy_ms, t.t_remote_decoded_ms, t.t_local_pred_ms,
        t.t_remote_pred_ms, t.probe_ms);
    return r;
}

Status writeTelemetryCsv(const std::string& path, const std::string& design,
                         const std::vector<FrameTelemetry>& frames) {
    std::ofstream out(path);
    if (!out)
        return makeError("cannot write " + path);
    out << telemetryCsvHeader();
    for (const FrameTelemetry& t : frames)
        out << telemetryCsvRow(design, t);
    if (!out)
        return makeError("error writing " + path);
    return {};
}

}  // namespace qvr::runtime
