// The run summary: nearest-rank percentiles, the start-up left out, a bounded MTP store.
#include "qvr/core/run_summary.h"

#include <algorithm>
#include <cmath>

namespace qvr {

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

FrameSummarizer::FrameSummarizer(int warmup_frames, size_t exact_mtp_frames)
    : m_warmup(warmup_frames > 0 ? static_cast<size_t>(warmup_frames) : 0),
      m_exact_mtp_frames(exact_mtp_frames) {
    m_startup.reserve(m_warmup);
}

void FrameSummarizer::add(const FrameSample& f) {
    const bool new_layers = f.shown_frame > m_newest_shown;
    m_newest_shown = std::max(m_newest_shown, f.shown_frame);
    if (!m_startup_done) {
        // The first m_warmup frames, and then every frame that still shows none of the
        // server's layers (RunStats::warmup_frames).
        const bool no_remote_yet =
            m_warmup > 0 && (f.remote_requested || f.remote_withheld) && !f.remote_shown;
        if (m_startup.size() < m_warmup ||
            (no_remote_yet && m_startup.size() < kMaxStartupFrames)) {
            m_startup.push_back(f);
            return;
        }
        // A frame past the start-up: the frames held were the start-up, left out.
        m_startup_done = true;
        m_s.warmup_frames = static_cast<int>(m_startup.size());
        for (const FrameSample& s : m_startup)
            m_s.startup_mtp_ms_max = std::max(m_s.startup_mtp_ms_max, s.mtp_ms);
        std::vector<FrameSample>().swap(m_startup);
    }
    count(f, new_layers);
}

void FrameSummarizer::count(const FrameSample& f, bool new_layers) {
    if (m_s.frames == 0)
        m_first_pose_ms = f.pose_ms;
    m_last_frame_display_ms = f.display_ms;
    ++m_s.frames;
    if (f.display_ms >= 0.0) {
        ++m_s.frames_displayed;
        if (m_first_display_ms < 0.0)
            m_first_display_ms = f.display_ms;
        m_last_display_ms = f.display_ms;
    }
    if (f.reused)
        ++m_s.frames_reused;
    if (new_layers)
        ++m_s.frames_new_layers;
    if (f.fallback_local)
        m_s.frames_fallback_local += 1;
    m_mtp_sum += f.mtp_ms;
    m_mtp_min = m_s.frames == 1 ? f.mtp_ms : std::min(m_mtp_min, f.mtp_ms);
    m_mtp_max = m_s.frames == 1 ? f.mtp_ms : std::max(m_mtp_max, f.mtp_ms);
    if (m_mtp_hist.empty() && m_mtp_exact.size() < m_exact_mtp_frames) {
        m_mtp_exact.push_back(f.mtp_ms);
    } else {
        if (m_mtp_hist.empty()) {
            m_mtp_hist.assign(kHistBins, 0);
            for (double v : m_mtp_exact)
                ++m_mtp_hist[histBin(v)];
            std::vector<double>().swap(m_mtp_exact);
        }
        ++m_mtp_hist[histBin(f.mtp_ms)];
    }
    m_bytes += f.bytes;
    m_e1 += f.e1_deg;
    m_t_local += f.t_local_ms;
    if (f.headset_busy_ms > 0.0) {
        m_busy += f.headset_busy_ms;
        ++m_s.headset_busy_frames;
    }
    m_uca += f.uca_ms;
    if (f.remote_requested) {
        m_t_remote += f.t_remote_ms;
        ++m_remote_frames;
        ++m_s.frames_remote_requested;
    }
}

double FrameSummarizer::mtpP99() const {
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

RunStats FrameSummarizer::finish() const {
    if (!m_startup_done && !m_startup.empty()) {
        // No frame past the start-up: summarize every frame.
        FrameSummarizer all(0, m_exact_mtp_frames);
        for (const FrameSample& f : m_startup)
            all.add(f);
        RunStats s = all.finish();
        s.startup_unfinished = true;
        return s;
    }
    RunStats s = m_s;
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
        s.wall_s = (m_last_frame_display_ms - m_first_pose_ms) * 1e-3;
    }
    if (m_remote_frames > 0)
        s.t_remote_ms_mean = m_t_remote / m_remote_frames;
    // Frames per second of scan-out: displays over the time between the first and the last,
    // so start-up does not count.
    if (s.frames_displayed > 1 && m_last_display_ms > m_first_display_ms)
        s.fps_mean = static_cast<double>(s.frames_displayed - 1) * 1000.0 /
                     (m_last_display_ms - m_first_display_ms);
    return s;
}

RunStats summarizeFrames(const std::vector<FrameSample>& frames, int warmup_frames) {
    FrameSummarizer r(warmup_frames);
    for (const FrameSample& f : frames)
        r.add(f);
    return r.finish();
}

}  // namespace qvr
