// A network-driven baseline (design "aimd"): EyeNexus's foveation controller (Wu et al., CoNEXT
// '25, arXiv 2509.11807; github.com/WuZemyp/EyeNexus-CoNEXT-25-, alvr/server/src/
// congestion_controller.rs). A delay-gradient detector in the style of WebRTC's trendline
// estimator reads each frame's one-way delay; the controller value C grows additively while the
// link keeps up and shrinks multiplicatively on overuse. EyeNexus streams the fovea, so its C
// sizes what is sent; here the link carries the periphery, so C sets the periphery's byte budget
// per frame and e1 is the smallest fovea whose periphery fits it. It sees no rendering cost:
// what LIWC adds is exactly that. Constants and their sources: docs/LIWC.md.
#pragma once

#include <deque>

#include "qvr/controller/policy.h"
#include "qvr/controller/remote_size_table.h"

namespace qvr {

struct AimdConfig {
    double e1_initial_deg = 5.0;  // the start LIWC also has (Fig. 14)
    double e1_min_deg = 1.0;
    double e1_max_deg = 90.0;
    // EyeNexus's controller: C in [2, 80]; +0.2 a frame while the link keeps up (+0.1 once a
    // capacity estimate exists), ×0.9 on overuse.
    double c_min = 2.0;
    double c_max = 80.0;
    double c_increase = 0.2;
    double c_increase_near_capacity = 0.1;
    double c_decrease_factor = 0.9;
    // The trendline detector (EyeNexus's TrendlineEstimator): 5 frames, smoothing 0.9, gain 4,
    // threshold 6, overuse only after 10 ms of it.
    int window_frames = 5;
    double smoothing = 0.9;
    double threshold_gain = 4.0;
    double threshold = 6.0;
    double overuse_time_ms = 10.0;
};

// The delay-gradient detector: per frame, the change of its one-way delay (arrival spacing minus
// send spacing), accumulated and smoothed, and the slope of that against arrival time over a
// window; a slope over the threshold for long enough is overuse (the queue grows), under
// −threshold underuse (it drains).
class DelayTrendDetector {
public:
    enum class Usage { Normal, Underusing, Overusing };
    explicit DelayTrendDetector(const AimdConfig& config) : m_config(config) {}
    // One frame: its send and arrival times (ms, any common origin on each side).
    Usage update(double send_ms, double arrival_ms);
    Usage usage() const { return m_usage; }
    double modifiedTrend() const { return m_modified_trend; }

private:
    AimdConfig m_config;
    bool m_have_previous = false;
    double m_previous_send_ms = 0.0, m_previous_arrival_ms = 0.0, m_first_arrival_ms = 0.0;
    int m_deltas = 0;
    double m_accumulated_ms = 0.0, m_smoothed_ms = 0.0;
    std::deque<std::pair<double, double>> m_history;  // (arrival − first arrival, smoothed delay)
    double m_trend = 0.0, m_previous_trend = 0.0, m_modified_trend = 0.0;
    double m_time_over_ms = -1.0;
    int m_overuse_count = 0;
    Usage m_usage = Usage::Normal;
};

class AimdPolicy final : public FoveaPolicy {
public:
    AimdPolicy(const WorkloadHeader& header, AimdConfig config = {});
    std::string_view name() const override { return "aimd"; }
    Decision decide(const WorkloadFrame& frame) override;
    void observe(const FrameMeasurement& m) override;
    double controller() const { return m_c; }

private:
    // Both eyes' periphery bits at e1 under the measured bits per pixel (scale-free: only the
    // ratio of the two layers' rates matters for the budget's e1).
    double peripheryBits(const Gaze& gaze, double e1_deg) const;
    void act(DelayTrendDetector::Usage usage);

    AimdConfig m_config;
    RemoteSizeTable m_sizes;
    DelayTrendDetector m_detector;
    double m_c = -1.0;  // set by the first decision, from e1_initial_deg
    enum class Action { Decrease, Hold, Increase } m_action = Action::Hold;
    // EyeNexus's link-capacity estimate of C at overuse (an EMA with its deviation).
    double m_capacity_c = -1.0;
    double m_capacity_deviation = 0.4;
    double m_bits_middle = 1.0, m_bits_outer = 1.0;  // per pixel, measured
};

std::unique_ptr<FoveaPolicy> makeAimdPolicy(const WorkloadHeader& header, AimdConfig config = {});

}  // namespace qvr
