// The headset's energy parts; the constants and their sources are in docs/EVAL.md.
#include "qvr/sim/energy.h"

#include <algorithm>

namespace qvr {

double radioPowerW(const RadioPower& radio, double goodput_bps) {
    if (goodput_bps <= 0.0)
        return 0.0;
    const double mbps = std::min(goodput_bps, kRadioFitTopBps) * 1e-6;
    return (radio.alpha_mw_per_mbps * mbps + radio.beta_mw) * 1e-3;
}

double radioEnergyMj(const RadioPower& radio, double goodput_bps, double duration_ms) {
    return radioPowerW(radio, goodput_bps) * std::max(0.0, duration_ms);
}

}  // namespace qvr
