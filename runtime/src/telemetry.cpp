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

namespace {

// Log-spaced MTP bins: [kHistMinMs · r^b, kHistMinMs · r^(b+1)), r = 1.001, up to 10⁷ ms.
constexpr double kHistMinMs = 1e-3;
constexpr double kHistRatio = 1.001;
const double kHistLogRatio = std::log(kHistRatio);
const size_t kHistBins = static_cast<size_t>(std::ceil(std::log(1e7 / kHistMinMs) / kHistLogRatio));

size_t histBin(double ms) {
    if (!(ms > kHistMinMs))
        return 0;
    const double b = std::floor(std::log(ms / kHistMinMs) / kHistLogRatio);
    return static_cast<size_t>(std::min(b, static_cast<double>(kHistBins - 1)));
}

}  // namespace

RunSummarizer::RunSummarizer(std::string design, int warmup_frames)
    : m_warmup(warmup_frames > 0 ? static_cast<size_t>(warmup_frames) : 0) {
    m_s.design = std::move(design);
    m_startup.reserve(m_warmup);
}

void RunSummarizer::add(const FrameTelemetry& t) {
    if (!m_startup_done) {
        // The first m_warmup frames, and then every frame that still shows none of the
        // server's layers (DesignSummary::warmup_frames).
        const bool no_remote_yet = m_warmup > 0 && t.remote_requested && t.shown_frame < 0;
        if (m_startup.size() < m_warmup ||
            (no_remote_yet && m_startup.size() < kMaxStartupFrames)) {
            m_startup.push_back(t);
            return;
        }
        // A frame past the start-up: the frames held were the start-up, left out.
        m_startup_done = true;
        m_s.warmup_frames = static_cast<int>(m_startup.size());
        for (const FrameTelemetry& s : m_startup)
            m_s.startup_mtp_ms_max = std::max(m_s.startup_mtp_ms_max, s.mtp_ms);
        std::vector<FrameTelemetry>().swap(m_startup);
    }
    count(t);
}

void RunSummarizer::count(const FrameTelemetry& t) {
    if (m_s.frames == 0)
        m_first_pose_ns = t.pose_ns;
    m_last_display_ns = t.display_ns;
    ++m_s.frames;
    if (t.display_ns >= 0) {
        ++m_s.frames_displayed;
        if (m_first_display < 0)
            m_first_display = t.display_ns;
        m_last_display = t.display_ns;
    }
    if (t.reused)
        ++m_s.frames_reused;
    if (t.fallback_local)
        m_s.frames_fallback_local += 1;
    m_mtp_sum += t.mtp_ms;
    m_mtp_min = m_s.frames == 1 ? t.mtp_ms : std::min(m_mtp_min, t.mtp_ms);
    m_mtp_max = m_s.frames == 1 ? t.mtp_ms : std::max(m_mtp_max, t.mtp_ms);
    if (m_mtp_hist.empty() && m_mtp_exact.size() < kExactMtpFrames) {
        m_mtp_exact.push_back(t.mtp_ms);
    } else {
        if (m_mtp_hist.empty()) {
            m_mtp_hist.assign(kHistBins, 0);
            for (double v : m_mtp_exact)
                ++m_mtp_hist[histBin(v)];
            std::vector<double>().swap(m_mtp_exact);
        }
        ++m_mtp_hist[histBin(t.mtp_ms)];
    }
    m_bytes += static_cast<double>(t.bytes);
    m_e1 += t.e1_deg;
    m_t_local += t.t_local_ms;
    if (t.headset_busy_ms > 0.0) {
        m_busy += t.headset_busy_ms;
        ++m_s.headset_busy_frames;
    }
    m_uca += t.uca_ms;
    if (t.remote_requested) {
        m_t_remote += t.t_remote_ms;
        ++m_remote_frames;
    }
}

double RunSummarizer::mtpP99() const {
    if (m_mtp_hist.empty())
        return percentile(m_mtp_exact, 99.0);
    // Nearest rank, as percentile(): the bin holding it, at its geometric middle, within the
    // values seen.
    const uint64_t rank = static_cast<uint64_t>(std::ceil(0.99 * static_cast<double>(m_s.frames)));
    uint64_t seen = 0;
    for (size_t b = 0; b < m_mtp_hist.size(); ++b) {
        seen += m_mtp_hist[b];
        if (seen >= rank)
            return std::clamp(kHistMinMs * std::pow(kHistRatio, double(b) + 0.5), m_mtp_min,
                              m_mtp_max);
    }
    return m_mtp_max;
}

DesignSummary RunSummarizer::finish() const {
    if (!m_startup_done && !m_startup.empty()) {
        // No frame past the start-up: summarize every frame.
        RunSummarizer all(m_s.design, 0);
        for (const FrameTelemetry& t : m_startup)
            all.add(t);
        DesignSummary s = all.finish();
        s.startup_unfinished = true;
        return s;
    }
    DesignSummary s = m_s;
    if (s.frames > 0) {
        const double n = static_cast<double>(s.frames);
        s.mtp_ms_mean = m_mtp_sum / n;
        s.mtp_ms_p99 = mtpP99();
        s.bytes_per_frame_mean = m_bytes / n;
        s.e1_deg_mean = m_e1 / n;
        s.t_local_ms_mean = m_t_local / n;
        if (s.headset_busy_frames > 0)
            s.headset_busy_ms_mean = m_busy / double(s.headset_busy_frames);
        s.uca_ms_mean = m_uca / n;
        s.wall_s = static_cast<double>(m_last_display_ns - m_first_pose_ns) * 1e-9;
    }
    if (m_remote_frames > 0)
        s.t_remote_ms_mean = m_t_remote / m_remote_frames;
    // Frames per second of scan-out: displays over the time between the first and the last,
    // so start-up does not count.
    if (s.frames_displayed > 1 && m_last_display > m_first_display)
        s.fps_mean = static_cast<double>(s.frames_displayed - 1) * 1e9 /
                     static_cast<double>(m_last_display - m_first_display);
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
         "t_local_pred_ms,t_remote_pred_ms,probe_ms,decode_ms,fovea_fragments\n";
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
        "{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.0f}\n",
        t.remote_done_ns, t.uca_start_ns, t.uca_end_ns, t.display_ns, t.bytes,
        int(t.remote_requested), int(t.reused), t.shown_frame, int(t.connected),
        int(t.fallback_local), t.t_local_ms, t.t_remote_ms, t.uca_ms, t.mtp_ms, t.throughput_bps,
        t.fovea_triangles, t.warp_deg, t.headset_busy_ms, t.t_remote_decoded_ms, t.t_local_pred_ms,
        t.t_remote_pred_ms, t.probe_ms, t.decode_ms, t.fovea_fragments);
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
