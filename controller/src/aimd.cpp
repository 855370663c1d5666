// EyeNexus's AIMD foveation controller as a Q-VR design (docs/LIWC.md "aimd").
#include "qvr/controller/aimd.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace qvr {

DelayTrendDetector::Usage DelayTrendDetector::update(double send_ms, double arrival_ms) {
    if (!m_have_previous) {
        m_have_previous = true;
        m_previous_send_ms = send_ms;
        m_previous_arrival_ms = arrival_ms;
        m_first_arrival_ms = arrival_ms;
        return m_usage;
    }
    const double send_delta_ms = send_ms - m_previous_send_ms;
    const double arrival_delta_ms = arrival_ms - m_previous_arrival_ms;
    m_previous_send_ms = send_ms;
    m_previous_arrival_ms = arrival_ms;
    m_deltas = std::min(m_deltas + 1, 1000);
    // The one-way delay's change, accumulated, through an exponential filter.
    m_accumulated_ms += arrival_delta_ms - send_delta_ms;
    m_smoothed_ms =
        m_config.smoothing * m_smoothed_ms + (1.0 - m_config.smoothing) * m_accumulated_ms;
    m_history.emplace_back(arrival_ms - m_first_arrival_ms, m_smoothed_ms);
    while (m_history.size() > static_cast<size_t>(m_config.window_frames))
        m_history.pop_front();
    if (m_history.size() == static_cast<size_t>(m_config.window_frames)) {
        // Least-squares slope of the smoothed delay against arrival time: ~(send rate −
        // capacity) / capacity; positive while the queue fills.
        double mx = 0.0, my = 0.0;
        for (const auto& [x, y] : m_history) {
            mx += x;
            my += y;
        }
        mx /= double(m_history.size());
        my /= double(m_history.size());
        double num = 0.0, den = 0.0;
        for (const auto& [x, y] : m_history) {
            num += (x - mx) * (y - my);
            den += (x - mx) * (x - mx);
        }
        if (den > 0.0)
            m_trend = num / den;
    }
    if (m_deltas < 2) {
        m_usage = Usage::Normal;
        return m_usage;
    }
    m_modified_trend = std::min(m_deltas, 60) * m_trend * m_config.threshold_gain;
    if (m_modified_trend > m_config.threshold) {
        m_time_over_ms =
            m_time_over_ms < 0.0 ? send_delta_ms / 2.0 : m_time_over_ms + send_delta_ms;
        ++m_overuse_count;
        if (m_time_over_ms > m_config.overuse_time_ms && m_overuse_count > 1 &&
            m_trend >= m_previous_trend) {
            m_time_over_ms = 0.0;
            m_overuse_count = 0;
            m_usage = Usage::Overusing;
        }
    } else if (m_modified_trend < -m_config.threshold) {
        m_time_over_ms = -1.0;
        m_overuse_count = 0;
        m_usage = Usage::Underusing;
    } else {
        m_time_over_ms = -1.0;
        m_overuse_count = 0;
        m_usage = Usage::Normal;
    }
    m_previous_trend = m_trend;
    return m_usage;
}

AimdPolicy::AimdPolicy(const WorkloadHeader& header, AimdConfig config)
    : m_config(config),
      m_sizes(header.profile, std::min(90.0, config.e1_max_deg)),
      m_detector(config) {}

double AimdPolicy::peripheryBits(const Gaze& gaze, double e1_deg) const {
    if (e1_deg >= m_sizes.coverDeg(gaze))
        return 0.0;
    const PeripheryShape p = m_sizes.lookup(gaze, e1_deg);
    return 2.0 * (p.middle_pixels * m_bits_middle + p.outer_pixels * m_bits_outer);
}

Decision AimdPolicy::decide(const WorkloadFrame& frame) {
    const double hi =
        std::max(m_config.e1_min_deg, std::min(m_config.e1_max_deg, m_sizes.coverDeg(frame.gaze)));
    const double full = std::max(1.0, peripheryBits(frame.gaze, m_config.e1_min_deg));
    if (m_c < 0.0) {
        const double start = std::clamp(m_config.e1_initial_deg, m_config.e1_min_deg, hi);
        m_c = std::clamp(m_config.c_max * peripheryBits(frame.gaze, start) / full, m_config.c_min,
                         m_config.c_max);
    }
    // C / C_max of the most the periphery can take: the smallest fovea whose periphery fits.
    const double budget = m_c / m_config.c_max * full;
    double e1 = hi;
    for (double e = m_config.e1_min_deg; e < hi; e += 0.25) {
        if (peripheryBits(frame.gaze, e) <= budget) {
            e1 = e;
            break;
        }
    }
    return {e1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
}

void AimdPolicy::act(DelayTrendDetector::Usage usage) {
    using Usage = DelayTrendDetector::Usage;
    if (usage == Usage::Normal)
        m_action = m_action == Action::Hold       ? Action::Increase
                   : m_action == Action::Decrease ? Action::Hold
                                                  : m_action;
    else if (usage == Usage::Overusing)
        m_action = Action::Decrease;
    else
        m_action = Action::Hold;
    const bool have_capacity = m_capacity_c > 0.0;
    const double spread =
        have_capacity ? 3.0 * std::sqrt(m_capacity_deviation * m_capacity_c) : 0.0;
    if (m_action == Action::Decrease) {
        m_c *= m_config.c_decrease_factor;
        if (have_capacity && m_c < std::max(0.1, m_capacity_c - spread))
            m_capacity_c = -1.0;
        // The capacity estimate: an EMA (weight 0.05) of C at overuse, with its deviation.
        const double alpha = 0.05;
        m_capacity_c = m_capacity_c < 0.0 ? m_c : (1.0 - alpha) * m_capacity_c + alpha * m_c;
        const double err = m_capacity_c - m_c;
        m_capacity_deviation = std::clamp(
            (1.0 - alpha) * m_capacity_deviation + alpha * err * err / std::max(m_capacity_c, 1.0),
            0.4, 2.5);
    } else if (m_action == Action::Increase) {
        if (have_capacity && m_c > m_capacity_c + spread)
            m_capacity_c = -1.0;
        m_c += m_capacity_c > 0.0 ? m_config.c_increase_near_capacity : m_config.c_increase;
    }
    m_c = std::clamp(m_c, m_config.c_min, m_config.c_max);
}

void AimdPolicy::observe(const FrameMeasurement& m) {
    // The layers' measured bits per pixel (the budget's e1 depends only on their ratio).
    const double b = 0.5;
    if (m.middle_pixels > 0.0 && m.middle_bytes > 0.0)
        m_bits_middle = (1.0 - b) * m_bits_middle + b * m.middle_bytes * 8.0 / m.middle_pixels;
    if (m.outer_pixels > 0.0 && m.outer_bytes > 0.0)
        m_bits_outer = (1.0 - b) * m_bits_outer + b * m.outer_bytes * 8.0 / m.outer_pixels;
    if (m_c < 0.0)
        return;
    // A periphery that missed the wait limit is a loss: decrease, as loss-based congestion
    // control does (on a link too slow for any frame to arrive in time the delay gives no sample).
    if (m.periphery_late) {
        act(DelayTrendDetector::Usage::Overusing);
        return;
    }
    // Otherwise a frame whose periphery did not all arrive gives no delay sample (EyeNexus
    // updates on each frame received).
    if (!(m.arrival_ms > 0.0) || m.arrival_ms < m.request_ms)
        return;
    act(m_detector.update(m.request_ms, m.arrival_ms));
}

std::unique_ptr<FoveaPolicy> makeAimdPolicy(const WorkloadHeader& header, AimdConfig config) {
    return std::make_unique<AimdPolicy>(header, config);
}

}  // namespace qvr
