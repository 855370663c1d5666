// Timing and power of the modelled headset hardware (paper Table 2, §4.3); constants and their
// sources: docs/MODEL.md.
#include "qvr/sim/hardware.h"

namespace qvr {

double MobileGpuConfig::samplesPerMs() const {
    // cycles per ms = MHz × 1000.
    return texture_units * samples_per_unit_per_cycle * render.freq_mhz * 1e3;
}

double MobileGpuConfig::passMs(double pixels, double samples_per_px) const {
    if (pixels <= 0.0)
        return 0.0;
    return pass_overhead_ms + pixels * samples_per_px / samplesPerMs();
}

double MobileGpuConfig::dynamicPowerW() const {
    const double f = render.freq_mhz;
    const double v_ratio = voltage(f) / voltage(500.0);
    return dynamic_power_w_at_500 * (f / 500.0) * v_ratio * v_ratio;
}

double MobileGpuConfig::staticPowerW() const {
    return static_power_w_at_500 * voltage(render.freq_mhz) / voltage(500.0);
}

HardwareConfig defaultHardware(double gpu_mhz) {
    HardwareConfig hw;
    hw.gpu.render.freq_mhz = gpu_mhz;
    return hw;
}

}  // namespace qvr
