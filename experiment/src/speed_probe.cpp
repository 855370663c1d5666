// The machine's speed at one moment (calibration.h SpeedProbe): a fixed headset frame and a
// fixed server frame, timed in a process of their own.
#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "calibration_side_mix.h"
#include "corun_load.h"

namespace qvr::experiment {

// The speed probe (calibration.h SpeedProbe): the same headset and server frames every time,
// each after its key frame, their medians.
Expected<SpeedSample> probeSpeed(SideMix& mix) {
    constexpr int n = SpeedProbe::kFrames;
    mix.restart();
    std::vector<double> headset, server;
    for (int k = 0; k <= n; ++k) {  // frame 0 decodes the streams' key frames, untimed
        const auto t0 = CalibrationClock::now();
        if (auto st = mix.headset(k); !st)
            return makeError("speed probe, headset frame: " + st.error());
        if (k > 0)
            headset.push_back(msSince(t0));
    }
    for (int k = 0; k < n + 2; ++k) {  // the key frame and the first P-frame untimed
        const auto t0 = CalibrationClock::now();
        if (auto st = mix.server(k); !st)
            return makeError("speed probe, server frame: " + st.error());
        if (k >= 2)
            server.push_back(msSince(t0));
    }
    auto median = [](std::vector<double>& v) {
        std::sort(v.begin(), v.end());
        return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    };
    return SpeedSample{median(headset), median(server)};
}

struct SpeedProbe::Impl {
    std::unique_ptr<CoRunLoad> child;
};

SpeedProbe::SpeedProbe(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SpeedProbe::~SpeedProbe() = default;

Expected<std::unique_ptr<SpeedProbe>> SpeedProbe::make(const CalibrateOptions& o) {
    // A process of its own, pinned to o.core, the same at the calibration and at the run: in
    // the calibrating process's renderer the probe read the headset frame up to 8% slower than
    // in the run's process, where the run's stages were not faster (docs/MODEL.md
    // §11).
    auto child = CoRunLoad::start(o, std::max(o.core, 0), "probe");
    if (!child)
        return makeError("speed probe: " + child.error());
    auto impl = std::make_unique<Impl>();
    impl->child = std::move(*child);
    return std::unique_ptr<SpeedProbe>(new SpeedProbe(std::move(impl)));
}

Expected<SpeedSample> SpeedProbe::measure() {
    return m_impl->child->probe();
}

std::array<double, 2> speedProbesSpreadPct(const std::vector<SpeedSample>& probes) {
    std::array<double, 2> out = {0.0, 0.0};
    if (probes.size() < 2)
        return out;
    for (size_t side = 0; side < 2; ++side) {
        double lo = 1e300, hi = 0.0;
        for (const SpeedSample& p : probes) {
            const double v = side == 0 ? p.headset_ms : p.server_ms;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        out[side] = 100.0 * (hi / lo - 1.0);
    }
    return out;
}

std::string speedProbesText(const std::vector<SpeedSample>& probes) {
    std::string s;
    for (const SpeedSample& p : probes)
        s += fmt::format("{}{:.2f}/{:.2f}", s.empty() ? "" : ", ", p.headset_ms, p.server_ms);
    if (probes.size() < 2)
        return s + " ms headset/server";
    const auto sp = speedProbesSpreadPct(probes);
    const double spread = std::max(sp[0], sp[1]);
    return s + fmt::format(" ms headset/server; spread {:.0f}%{}", spread,
                           spread > kUnsteadySpeedPct
                               ? " (the machine was unsteady while it was measured: "
                                 "calibrate again on a steady one)"
                               : "");
}

SpeedSample meanSpeed(const std::vector<SpeedSample>& probes) {
    SpeedSample mean;
    for (const SpeedSample& p : probes) {
        mean.headset_ms += p.headset_ms / double(probes.size());
        mean.server_ms += p.server_ms / double(probes.size());
    }
    return mean;
}

}  // namespace qvr::experiment
