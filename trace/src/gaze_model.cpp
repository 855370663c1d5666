// Seeded gaze model (paper §3.1: the fovea follows the gaze; §7: 120 Hz eye trackers):
// alternating fixations (or pursuits) and main-sequence saccades inside a bounding ellipse.
#include "qvr/trace/gaze_model.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace qvr {

namespace {

constexpr double kPi = 3.14159265358979323846;

// SplitMix64 + Box–Muller written out: std::*_distribution differ between standard libraries,
// and a trace must be the same for a seed everywhere.
class Rng {
public:
    explicit Rng(uint64_t seed) : m_state(seed) {}
    uint64_t next() {
        uint64_t z = (m_state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
    double normal() {
        const double u1 = 1.0 - uniform();  // (0, 1]
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
    }
    double logNormal(double median, double sigma) { return median * std::exp(sigma * normal()); }

private:
    uint64_t m_state;
};

bool inside(const GazeModelConfig& c, double x, double y) {
    const double u = x / c.bound_x_deg;
    const double v = y / c.bound_y_deg;
    return u * u + v * v <= 1.0;
}

double distance(const Gaze& a, const Gaze& b) {
    return std::hypot(b.x_deg - a.x_deg, b.y_deg - a.y_deg);
}

// Gaze angles are treated as planar over the ±25° range the model uses: the small-angle error
// of adding angle offsets is far below tracker accuracy (<1°, §7) for these amplitudes.
Gaze along(const Gaze& from, const Gaze& to, double fraction) {
    return {from.x_deg + (to.x_deg - from.x_deg) * fraction,
            from.y_deg + (to.y_deg - from.y_deg) * fraction};
}

// Shrinks the step from `from` toward `to` so the end point stays inside the ellipse.
Gaze clampToBounds(const GazeModelConfig& c, const Gaze& from, const Gaze& to) {
    if (inside(c, to.x_deg, to.y_deg))
        return to;
    double lo = 0.0;
    double hi = 1.0;
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        const Gaze g = along(from, to, mid);
        (inside(c, g.x_deg, g.y_deg) ? lo : hi) = mid;
    }
    return along(from, to, lo);
}

}  // namespace

double saccadeDurationMs(const GazeModelConfig& c, double a) {
    return c.duration_slope_ms_per_deg * a + c.duration_intercept_ms;
}

double saccadePeakVelocityDegS(const GazeModelConfig& c, double a) {
    return c.peak_velocity_max_deg_s * (1.0 - std::exp(-a / c.peak_velocity_c_deg));
}

namespace {
// The profile's peak/mean velocity ratio: the main sequence's, kept where a ramp-plateau-ramp
// profile exists.
double peakToMeanRatio(const GazeModelConfig& c, double a) {
    if (!(a > 1e-9))
        return 2.0;  // no movement: any valid profile
    const double mean = a / (saccadeDurationMs(c, a) / 1000.0);
    return std::clamp(saccadePeakVelocityDegS(c, a) / mean, 1.05, 2.0);
}
}  // namespace

Status validateGazeModelConfig(const GazeModelConfig& c) {
    auto range = [](double v, double lo, double hi, const char* what) -> Status {
        if (!(v >= lo && v <= hi))
            return makeError(fmt::format("gaze model: {} = {} outside [{}, {}]", what, v, lo, hi));
        return Status::success();
    };
    for (Status s :
         {range(c.sample_rate_hz, 1, 2000, "sample_rate_hz"),
          range(c.fixation_median_ms, 10, 10000, "fixation_median_ms"),
          range(c.fixation_sigma, 0, 3, "fixation_sigma"),
          range(c.fixation_min_ms, 1, c.fixation_max_ms, "fixation_min_ms"),
          range(c.fixation_max_ms, 1, 60000, "fixation_max_ms"),
          range(c.saccade_median_deg, 0.1, 60, "saccade_median_deg"),
          range(c.saccade_sigma, 0, 3, "saccade_sigma"),
          range(c.saccade_min_deg, 0.01, c.saccade_max_deg, "saccade_min_deg"),
          range(c.saccade_max_deg, 0.01, 90, "saccade_max_deg"),
          range(c.duration_slope_ms_per_deg, 0, 20, "duration_slope_ms_per_deg"),
          range(c.duration_intercept_ms, 1, 200, "duration_intercept_ms"),
          range(c.peak_velocity_max_deg_s, 10, 2000, "peak_velocity_max_deg_s"),
          range(c.peak_velocity_c_deg, 0.1, 100, "peak_velocity_c_deg"),
          range(c.pursuit_probability, 0, 1, "pursuit_probability"),
          range(c.pursuit_median_deg_s, 0.1, 100, "pursuit_median_deg_s"),
          range(c.pursuit_max_deg_s, 0.1, 100, "pursuit_max_deg_s"),
          range(c.bound_x_deg, 1, 80, "bound_x_deg"), range(c.bound_y_deg, 1, 80, "bound_y_deg"),
          range(c.tracker_noise_deg, 0, 5, "tracker_noise_deg")}) {
        if (!s)
            return s;
    }
    return Status::success();
}

double saccadeProgress(const GazeModelConfig& c, double a, double tau) {
    tau = std::clamp(tau, 0.0, 1.0);
    // Peak/mean velocity ratio r fixes the ramp fraction f: a plateau with raised-cosine ramps
    // of fraction f each covers (1 − f) of peak × duration, so r = 1 / (1 − f). Real saccades
    // have r ≈ 1.5–1.7; with c = 7° the main-sequence pair gives r in that range, and the clamp
    // keeps the profile valid for any configuration.
    const double f = 1.0 - 1.0 / peakToMeanRatio(c, a);
    auto ramp = [f](double u) { return 0.5 * (u - f / kPi * std::sin(kPi * u / f)); };
    double g = 0.0;
    if (tau <= f)
        g = ramp(tau);
    else if (tau <= 1.0 - f)
        g = 0.5 * f + (tau - f);
    else
        g = (1.0 - f) - ramp(1.0 - tau);
    return g / (1.0 - f);
}

Expected<GazeTrace> generateGaze(const GazeModelConfig& c, uint64_t seed, int samples) {
    if (Status s = validateGazeModelConfig(c); !s)
        return makeError(s.error());
    if (samples < 1 || samples > 100'000'000)
        return makeError(fmt::format("gaze samples {} outside [1, 1e8]", samples));
    Rng rng(seed);
    GazeTrace trace;
    const double step_ms = 1000.0 / c.sample_rate_hz;
    const double end_ms = (samples - 1) * step_ms;

    // Start somewhere in the central third of the bounds.
    Gaze at{(rng.uniform() - 0.5) * c.bound_x_deg * 0.66,
            (rng.uniform() - 0.5) * c.bound_y_deg * 0.66};
    double t = 0.0;
    // Events first (the ground truth), then samples read off them.
    while (t <= end_ms) {
        // A fixation, or a pursuit instead.
        GazeEvent hold;
        hold.start_ms = t;
        hold.duration_ms = std::clamp(rng.logNormal(c.fixation_median_ms, c.fixation_sigma),
                                      c.fixation_min_ms, c.fixation_max_ms);
        hold.from = at;
        hold.to = at;
        if (rng.uniform() < c.pursuit_probability) {
            const double speed =
                std::min(rng.logNormal(c.pursuit_median_deg_s, 0.5), c.pursuit_max_deg_s);
            const double dir = 2.0 * kPi * rng.uniform();
            const double len = speed * hold.duration_ms / 1000.0;
            const Gaze want{at.x_deg + len * std::cos(dir), at.y_deg + len * std::sin(dir)};
            hold.kind = GazeEventKind::kPursuit;
            hold.to = clampToBounds(c, at, want);
            hold.amplitude_deg = distance(hold.from, hold.to);
            hold.peak_velocity_deg_s = hold.amplitude_deg / (hold.duration_ms / 1000.0);
        }
        trace.events.push_back(hold);
        t += hold.duration_ms;
        at = hold.to;
        if (t > end_ms)
            break;

        // A saccade: draw amplitude and direction; redraw directions whose target leaves the
        // bounds, shrinking the amplitude after a few misses (near the edge only short or
        // inward saccades fit: the central bias of head-free viewing, where large gaze shifts
        // come with a head turn instead).
        double amp = std::clamp(rng.logNormal(c.saccade_median_deg, c.saccade_sigma),
                                c.saccade_min_deg, c.saccade_max_deg);
        Gaze target = at;
        bool found = false;
        for (int attempt = 0; attempt < 48 && !found; ++attempt) {
            if (attempt >= 8)
                amp = std::max(c.saccade_min_deg, amp * 0.85);
            const double dir = 2.0 * kPi * rng.uniform();
            target = {at.x_deg + amp * std::cos(dir), at.y_deg + amp * std::sin(dir)};
            found = inside(c, target.x_deg, target.y_deg);
        }
        if (!found)
            continue;  // wedged against the bounds: fixate again
        GazeEvent sac;
        sac.kind = GazeEventKind::kSaccade;
        sac.start_ms = t;
        sac.from = at;
        sac.to = target;
        sac.amplitude_deg = amp;
        sac.duration_ms = saccadeDurationMs(c, amp);
        sac.peak_velocity_deg_s = peakToMeanRatio(c, amp) * amp / (sac.duration_ms / 1000.0);
        trace.events.push_back(sac);
        t += sac.duration_ms;
        at = target;
    }

    trace.samples.reserve(static_cast<size_t>(samples));
    size_t e = 0;
    for (int k = 0; k < samples; ++k) {
        const double ts = k * step_ms;
        while (e + 1 < trace.events.size() && trace.events[e + 1].start_ms <= ts)
            ++e;
        const GazeEvent& ev = trace.events[e];
        const double tau = ev.duration_ms > 0 ? (ts - ev.start_ms) / ev.duration_ms : 1.0;
        double frac = std::clamp(tau, 0.0, 1.0);
        if (ev.kind == GazeEventKind::kSaccade)
            frac = saccadeProgress(c, ev.amplitude_deg, tau);
        Gaze g = along(ev.from, ev.to, frac);
        if (c.tracker_noise_deg > 0) {
            g.x_deg += c.tracker_noise_deg * rng.normal();
            g.y_deg += c.tracker_noise_deg * rng.normal();
        }
        trace.samples.push_back({ts, g});
    }
    return trace;
}

Gaze gazeAt(const GazeTrace& trace, double t_ms) {
    QVR_CHECK(!trace.samples.empty());
    const auto& s = trace.samples;
    auto it = std::upper_bound(s.begin(), s.end(), t_ms,
                               [](double t, const GazeSample& g) { return t < g.t_ms; });
    if (it == s.begin())
        return s.front().gaze;
    return (it - 1)->gaze;
}

}  // namespace qvr
