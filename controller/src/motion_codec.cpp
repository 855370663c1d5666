// LIWC's motion codec (paper §4.1): 6 bits of head degree-of-freedom change, 4 of gaze motion.
#include "qvr/controller/motion_codec.h"

#include <cmath>

namespace qvr {

namespace {
double wrapDeg(double d) {
    while (d > 180.0)
        d -= 360.0;
    while (d < -180.0)
        d += 360.0;
    return d;
}
}  // namespace

uint16_t encodeMotion(const Pose& previous_head, const Pose& head, const Gaze& previous_gaze,
                      const Gaze& gaze, const MotionThresholds& t) {
    const EulerDeg a = eulerDegFromQuat(previous_head.orientation);
    const EulerDeg b = eulerDegFromQuat(head.orientation);
    uint16_t code = 0;
    if (std::fabs(wrapDeg(b.yaw_deg - a.yaw_deg)) > t.rotation_deg)
        code |= 1u << 0;
    if (std::fabs(wrapDeg(b.pitch_deg - a.pitch_deg)) > t.rotation_deg)
        code |= 1u << 1;
    if (std::fabs(wrapDeg(b.roll_deg - a.roll_deg)) > t.rotation_deg)
        code |= 1u << 2;
    const glm::vec3 dp = head.position_m - previous_head.position_m;
    if (std::fabs(dp.x) > t.translation_m)
        code |= 1u << 3;
    if (std::fabs(dp.y) > t.translation_m)
        code |= 1u << 4;
    if (std::fabs(dp.z) > t.translation_m)
        code |= 1u << 5;
    const double gx = gaze.x_deg - previous_gaze.x_deg;
    const double gy = gaze.y_deg - previous_gaze.y_deg;
    if (std::fabs(gx) > t.gaze_deg) {
        code |= 1u << 6;
        if (gx > 0)
            code |= 1u << 7;
    }
    if (std::fabs(gy) > t.gaze_deg) {
        code |= 1u << 8;
        if (gy > 0)
            code |= 1u << 9;
    }
    return code;
}

MotionFields decodeMotion(uint16_t code) {
    auto bit = [code](int i) { return ((code >> i) & 1u) != 0; };
    MotionFields f;
    f.yaw = bit(0);
    f.pitch = bit(1);
    f.roll = bit(2);
    f.x = bit(3);
    f.y = bit(4);
    f.z = bit(5);
    f.gaze_h = bit(6);
    f.gaze_right = bit(7);
    f.gaze_v = bit(8);
    f.gaze_up = bit(9);
    return f;
}

}  // namespace qvr
