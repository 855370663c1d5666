// When the headset calls its render server silent. Shared by the runtime's headset
// (runtime/src/headset_client.cpp, step 5) and the simulator's model of it
// (sim/src/runtime_model.cpp), so that both make the same call on the same stream times.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

namespace qvr {

// A server is silent when nothing has come from it for longer than the wait limit and for
// longer than twice its recent spacing between streams (the median of the last kGaps gaps).
// The second condition keeps a slow server from being called silent between two of its
// streams: one whose streams come every 260 ms is slow, not stalled, and calling it silent
// whenever a gap passes 250 ms flipped the headset between waiting the limit (3.5 FPS) and
// re-warping at the refresh rate (25 FPS) on a 15% change in the server's speed (docs/MODEL.md
// §8, "A slow server is not a silent one"). A server whose streams come faster than half the
// limit, every design but a whole-frame one on a slow server, is judged on the limit alone.
class SilenceDetector {
public:
    static constexpr size_t kGaps = 8;
    static constexpr double kSpacings = 2.0;

    // A new session at t_ms: it has a whole threshold to deliver its first stream, and the old
    // session's spacing says nothing about the new one's.
    void restart(double t_ms) {
        m_last_ms = t_ms;
        m_have_stream = false;
        m_count = 0;
        m_next = 0;
    }

    // A stream taken from the transport at t_ms.
    void onStream(double t_ms) {
        if (m_have_stream) {
            m_gaps[m_next] = std::max(0.0, t_ms - m_last_ms);
            m_next = (m_next + 1) % kGaps;
            m_count = std::min(m_count + 1, kGaps);
        }
        m_last_ms = t_ms;
        m_have_stream = true;
    }

    // How long the server may stay quiet before it is silent, for a wait limit of limit_ms.
    double thresholdMs(double limit_ms) const {
        if (m_count == 0)
            return limit_ms;
        std::array<double, kGaps> g = m_gaps;
        const auto mid = g.begin() + static_cast<std::ptrdiff_t>(m_count / 2);
        std::nth_element(g.begin(), mid, g.begin() + static_cast<std::ptrdiff_t>(m_count));
        return std::max(limit_ms, kSpacings * *mid);
    }

    bool silent(double now_ms, double limit_ms) const {
        return now_ms - m_last_ms > thresholdMs(limit_ms);
    }

    // The newest stream, or the session's start before any.
    double lastMs() const { return m_last_ms; }

private:
    std::array<double, kGaps> m_gaps{};
    size_t m_count = 0;
    size_t m_next = 0;
    double m_last_ms = 0.0;
    bool m_have_stream = false;
};

}  // namespace qvr
