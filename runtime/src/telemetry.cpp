// Telemetry: CSV rows and the per-design summary `qvr run` writes.
#include "qvr/runtime/telemetry.h"

#include <string>

#include <fmt/format.h>

#include "qvr/core/text_file.h"

namespace qvr::runtime {

FrameSample frameSample(const FrameTelemetry& t) {
    FrameSample f;
    f.pose_ms = static_cast<double>(t.pose_ns) * 1e-6;
    f.display_ms = static_cast<double>(t.display_ns) * 1e-6;  // −1 ns: not displayed
    f.mtp_ms = t.mtp_ms;
    f.bytes = static_cast<double>(t.bytes);
    f.e1_deg = t.e1_deg;
    f.t_local_ms = t.t_local_ms;
    f.t_remote_ms = t.t_remote_ms;
    f.headset_busy_ms = t.headset_busy_ms;
    f.uca_ms = t.uca_ms;
    f.remote_requested = t.remote_requested;
    f.remote_withheld = t.request_withheld;
    f.remote_shown = t.shown_frame >= 0;
    f.reused = t.reused;
    f.shown_frame = t.shown_frame;
    f.fallback_local = t.fallback_local;
    return f;
}

RunSummarizer::RunSummarizer(std::string design, int warmup_frames)
    : m_design(std::move(design)), m_frames(warmup_frames) {}

void RunSummarizer::add(const FrameTelemetry& t) {
    m_frames.add(frameSample(t));
}

DesignSummary RunSummarizer::finish() const {
    DesignSummary s;
    static_cast<RunStats&>(s) = m_frames.finish();
    s.design = m_design;
    return s;
}

DesignSummary summarizeRun(const std::string& design, const std::vector<FrameTelemetry>& all,
                           int warmup_frames) {
    RunSummarizer r(design, warmup_frames);
    for (const FrameTelemetry& t : all)
        r.add(t);
    return r.finish();
}

std::string telemetryCsvHeader() {
    std::string h =
        "design,frame,e1_deg,e2_deg,pose_ns,decision_ns,local_start_ns,local_end_ns,request_ns";
    for (int s = 0; s < kStreams; ++s)
        h += fmt::format(",stream{}_rx_ns,stream{}_decoded_ns", s, s);
    h += ",remote_done_ns,uca_start_ns,uca_end_ns,display_ns,bytes,remote_requested,reused,"
         "shown_frame,connected,fallback_local,t_local_ms,t_remote_ms,uca_ms,mtp_ms,"
         "throughput_bps,fovea_triangles,warp_deg,headset_busy_ms,t_remote_decoded_ms,"
         "t_local_pred_ms,t_remote_pred_ms,probe_ms,decode_ms,fovea_fragments,"
         "request_withheld,server_ms\n";
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
        "{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.0f},{},{:.3f}\n",
        t.remote_done_ns, t.uca_start_ns, t.uca_end_ns, t.display_ns, t.bytes,
        int(t.remote_requested), int(t.reused), t.shown_frame, int(t.connected),
        int(t.fallback_local), t.t_local_ms, t.t_remote_ms, t.uca_ms, t.mtp_ms, t.throughput_bps,
        t.fovea_triangles, t.warp_deg, t.headset_busy_ms, t.t_remote_decoded_ms, t.t_local_pred_ms,
        t.t_remote_pred_ms, t.probe_ms, t.decode_ms, t.fovea_fragments, int(t.request_withheld),
        t.server_ms);
    return r;
}

Status writeTelemetryCsv(const std::string& path, const std::string& design,
                         const std::vector<FrameTelemetry>& frames) {
    std::string text = telemetryCsvHeader();
    for (const FrameTelemetry& t : frames)
        text += telemetryCsvRow(design, t);
    return writeTextFile(path, text);
}

}  // namespace qvr::runtime
