// Energy of one frame on the headset (paper §6.3, Fig. 15): the GPU, the radio while it
// receives, and the rest (UCA, LIWC), each from a published power figure (docs/EVAL.md).
#pragma once

#include "qvr/sim/network.h"

namespace qvr {

// Huang et al. (MobiSys 2012, Table 3) fitted P = α·R + β to downlink rates of at most about
// 20 Mbit/s. Extrapolated to the goodputs we simulate (69–344 Mbit/s) the line reaches 5–19 W,
// far above what a phone's radio can draw. Above the measured range the radio draws the power
// at its top: the rate saturates, the power does not keep rising.
inline constexpr double kRadioFitTopBps = 20e6;

// The radio's power while it receives at `goodput_bps`, watts: α·min(R, 20 Mbit/s) + β.
double radioPowerW(const RadioPower& radio, double goodput_bps);
// A transfer's energy, millijoules: the power at its goodput over its duration.
double radioEnergyMj(const RadioPower& radio, double goodput_bps, double duration_ms);

// Energy of one frame, millijoules; total() is the sum of the parts and nothing else.
struct FrameEnergy {
    double gpu_dynamic_mj = 0.0;  // dynamic power × GPU busy time
    double gpu_static_mj = 0.0;   // leakage × frame period
    double radio_mj = 0.0;        // radio power at the goodput × transfer time
    double uca_mj = 0.0;          // 94 mW × unit-busy time
    double liwc_mj = 0.0;         // 25 mW × frame period
    double gpuMj() const { return gpu_dynamic_mj + gpu_static_mj; }
    double radioMj() const { return radio_mj; }
    double otherMj() const { return uca_mj + liwc_mj; }
    double total() const { return gpuMj() + radioMj() + otherMj(); }
};

}  // namespace qvr
