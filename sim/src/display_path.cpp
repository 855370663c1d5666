// Display-path DRAM traffic; the reading of Table 2 is in display_path.h and docs/EVAL.md.
#include "qvr/sim/display_path.h"

#include <algorithm>

namespace qvr {

double dramBytesPerMs() {
    // cycles per ms = MHz × 1000.
    return kDramBytesPerCyclePerChannel * kDramChannels * kDramClockMhz * 1e3;
}

double dramMs(double bytes) {
    return std::max(0.0, bytes) / dramBytesPerMs();
}

double gpuPassDramBytes(double output_pixels, double samples_per_px) {
    return std::max(0.0, output_pixels) * (samples_per_px + 1.0) * kPixelBytes;
}

double ucaDramBytes(double layer_pixels, double display_pixels) {
    return (std::max(0.0, layer_pixels) + std::max(0.0, display_pixels)) * kPixelBytes;
}

}  // namespace qvr
