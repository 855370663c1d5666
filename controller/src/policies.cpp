// The policies LIWC is compared with (paper §6): fixed e1 (FFR), the software-reactive Q-VR
// that only sees measured latencies late, and the oracle that knows the true cost curve.
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "qvr/controller/policy.h"
#include "qvr/controller/remote_size_table.h"

namespace qvr {

FrameMeasurement measureFrame(int64_t index, const LayerPlan& plan, const FrameCost& cost,
                              double throughput_bps) {
    FrameMeasurement m;
    m.index = index;
    m.e1_deg = plan.e1_deg;
    m.t_local_ms = cost.local_ms;
    m.t_remote_ms = cost.remote_ms;
    m.triangles_local = cost.triangles_local;
    m.pixels_local = cost.pixels_local;
    m.middle_bytes = cost.bytes.middle;
    m.outer_bytes = cost.bytes.outer;
    // Plans count pixels per eye; both eyes are rendered and sent.
    m.middle_pixels = 2.0 * static_cast<double>(plan.middle_pixels);
    m.outer_pixels = 2.0 * static_cast<double>(plan.outer_pixels);
    m.s1 = plan.s1;
    m.s2 = plan.s2;
    m.throughput_bps = cost.remote_ms > 0 ? throughput_bps : 0.0;
    return m;
}

Decision FixedPolicy::decide(const WorkloadFrame&) {
    return {m_e1_deg, std::numeric_limits<double>::quiet_NaN(),
            std::numeric_limits<double>::quiet_NaN()};
}

namespace {

class SoftwareReactivePolicy final : public FoveaPolicy {
public:
    SoftwareReactivePolicy(const WorkloadHeader& header, SoftwareReactiveConfig config)
        : m_config(config), m_sizes(header.profile), m_e1_deg(config.e1_initial_deg) {}

    std::string_view name() const override { return "sw"; }

    Decision decide(const WorkloadFrame& frame) override {
        ++m_frame;
        // Only measurements at least lag_frames old have reached software.
        const FrameMeasurement* m = nullptr;
        while (!m_pending.empty() && m_pending.front().index <= m_frame - m_config.lag_frames) {
            m_latest = m_pending.front();
            m_have_latest = true;
            m_pending.pop_front();
        }
        if (m_have_latest)
            m = &m_latest;
        Decision d;
        d.e1_deg = m_e1_deg;
        d.t_local_pred_ms = std::numeric_limits<double>::quiet_NaN();
        d.t_remote_pred_ms = std::numeric_limits<double>::quiet_NaN();
        if (m == nullptr || m->t_local_ms <= 0.0)
            return d;
        // Scale the old measurement to candidate sizes: local time with the fovea's pixels,
        // remote time with the periphery's bytes under the measured bits per pixel.
        const PeripheryShape at_m = m_sizes.lookup(frame.gaze, m->e1_deg);
        const double fovea_m = std::max(1.0, at_m.fovea_pixels);
        const double bits_mid = m->middle_pixels > 0 ? m->middle_bytes * 8.0 / m->middle_pixels : 0;
        const double bits_out = m->outer_pixels > 0 ? m->outer_bytes * 8.0 / m->outer_pixels : 0;
        const double bps = m->throughput_bps > 0 ? m->throughput_bps : 1.0;
        auto predict = [&](double e, double& tl, double& tr) {
            const PeripheryShape p = m_sizes.lookup(frame.gaze, e);
            tl = m->t_local_ms * p.fovea_pixels / fovea_m;
            const double bytes =
                2.0 * (p.middle_pixels * bits_mid + p.outer_pixels * bits_out) / 8.0;
            tr = bytes * 8.0 / bps * 1000.0;
        };
        const double cover = m_sizes.coverDeg(frame.gaze);
        const double lo = std::max(m_config.e1_min_deg, m_e1_deg - m_config.max_step_deg);
        const double hi = std::min({m_config.e1_max_deg, cover, m_e1_deg + m_config.max_step_deg});
        double best_e = m_e1_deg, best = std::numeric_limits<double>::infinity();
        for (double e = lo; e <= hi + 1e-9; e += 0.1) {
            double tl, tr;
            predict(e, tl, tr);
            const double cost = std::max(tl, tr);
            if (cost < best) {
                best = cost;
                best_e = e;
                d.t_local_pred_ms = tl;
                d.t_remote_pred_ms = tr;
            }
        }
        m_e1_deg = best_e;
        d.e1_deg = best_e;
        return d;
    }

    void observe(const FrameMeasurement& m) override { m_pending.push_back(m); }

private:
    SoftwareReactiveConfig m_config;
    RemoteSizeTable m_sizes;
    double m_e1_deg;
    int64_t m_frame = -1;
    std::deque<FrameMeasurement> m_pending;
    FrameMeasurement m_latest;
    bool m_have_latest = false;
};

class OraclePolicy final : public FoveaPolicy {
public:
    OraclePolicy(const WorkloadHeader& header, const CostModel& truth, double e1_min, double e1_max)
        : m_truth(truth), m_geometry(header.profile), m_e1_min(e1_min), m_e1_max(e1_max) {}

    std::string_view name() const override { return "oracle"; }

    Decision decide(const WorkloadFrame& frame) override {
        const double hi = std::min(m_e1_max, m_geometry.coverEccentricityDeg(frame.gaze));
        auto cost = [&](double e) { return m_truth.cost(frame, e).frameMs(); };
        double best_e = m_e1_min, best = cost(m_e1_min);
        auto consider = [&](double e) {
            const double c = cost(e);
            if (c < best) {
                best = c;
                best_e = e;
            }
        };
        for (double e = m_e1_min + 1.0; e < hi; e += 1.0)
            consider(e);
        consider(hi);
        // max(T_local, T_remote) is unimodal near its minimum: refine by golden section.
        // Whole-pixel framebuffers make T_remote a staircase in e1 with dips a bracket search
        // can settle in; refine by scanning ever finer grids around the best point instead.
        for (const auto& [step, reach] : {std::pair{0.1, 10}, std::pair{0.01, 25}}) {
            const double centre = best_e;
            for (int k = -reach; k <= reach; ++k) {
                const double e = centre + k * step;
                if (e >= m_e1_min && e <= hi)
                    consider(e);
            }
        }
        const FrameCost c = m_truth.cost(frame, best_e);
        return {best_e, c.local_ms, c.remote_ms};
    }

    void observe(const FrameMeasurement&) override {}

private:
    const CostModel& m_truth;
    EyeGeometry m_geometry;
    double m_e1_min;
    double m_e1_max;
};

}  // namespace

std::unique_ptr<FoveaPolicy> makeSoftwareReactivePolicy(const WorkloadHeader& header,
                                                        SoftwareReactiveConfig config) {
    return std::make_unique<SoftwareReactivePolicy>(header, config);
}

std::unique_ptr<FoveaPolicy> makeOraclePolicy(const WorkloadHeader& header, const CostModel& truth,
                                              double e1_min_deg, double e1_max_deg) {
    return std::make_unique<OraclePolicy>(header, truth, e1_min_deg, e1_max_deg);
}

}  // namespace qvr
