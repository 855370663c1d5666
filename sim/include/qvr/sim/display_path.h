// The display path's memory traffic (paper §4.2, Table 2): composition and ATW read the layers
// from DRAM and write the display image back, on the GPU as two passes or on the UCA as one.
#pragma once

namespace qvr {

// Table 2: "DRAM bandwidth 16 bytes/cycle, 8 channel". Read as 16 bytes per cycle on each of
// the 8 channels at the 500 MHz reference clock: 64 GB/s. (Read as 16 bytes per cycle in all,
// 8 GB/s, one stereo 1920×2160 ATW pass alone would take 8.3 ms and no design could hold the
// 90 FPS of Fig. 14(b).) The memory clock does not follow the GPU's DVFS.
inline constexpr double kDramBytesPerCyclePerChannel = 16.0;
inline constexpr int kDramChannels = 8;
inline constexpr double kDramClockMhz = 500.0;
// A display or layer pixel in DRAM: RGBA8.
inline constexpr double kPixelBytes = 4.0;

double dramBytesPerMs();
double dramMs(double bytes);

// One GPU screen-space pass: `samples_per_px` texels read and one pixel written per output pixel.
double gpuPassDramBytes(double output_pixels, double samples_per_px);
// The UCA's fused pass (§4.2): every layer pixel read once, every display pixel written once.
double ucaDramBytes(double layer_pixels, double display_pixels);

}  // namespace qvr
