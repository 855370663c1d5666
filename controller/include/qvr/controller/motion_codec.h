// LIWC's motion codec (paper §4.1): the change of the user's motion between two frames as a
// 10-bit index — one bit per head degree of freedom that changed, four bits for the gaze.
#pragma once

#include <cstdint>

#include "qvr/core/pose.h"
#include "qvr/foveation/eye_geometry.h"

namespace qvr {

inline constexpr int kMotionBits = 10;
inline constexpr int kMotionCodes = 1 << kMotionBits;

// Bit layout (LSB first):
//   0 yaw changed   1 pitch changed   2 roll changed     (|Δangle| > rotation_deg)
//   3 x moved       4 y moved         5 z moved          (|Δposition| > translation_m)
//   6 gaze moved horizontally   7 …and to the right (sign, only meaningful with bit 6)
//   8 gaze moved vertically     9 …and upwards      (sign, only meaningful with bit 8)
// Sign bits are cleared when their axis did not move, so each motion has one code.
struct MotionThresholds {
    double rotation_deg = 0.25;    // per frame; 22.5 °/s at 90 Hz
    double translation_m = 0.002;  // per frame; 0.18 m/s at 90 Hz
    double gaze_deg = 0.5;         // per frame
};

uint16_t encodeMotion(const Pose& previous_head, const Pose& head, const Gaze& previous_gaze,
                      const Gaze& gaze, const MotionThresholds& thresholds = {});

struct MotionFields {
    bool yaw = false, pitch = false, roll = false;
    bool x = false, y = false, z = false;
    bool gaze_h = false, gaze_right = false, gaze_v = false, gaze_up = false;
};
MotionFields decodeMotion(uint16_t code);

}  // namespace qvr
