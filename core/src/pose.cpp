// Pose helpers: Euler decomposition for the motion codec and trace files.
#include "qvr/core/pose.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace qvr {

namespace {
constexpr double kDegPerRad = 57.29577951308232;
}

glm::quat quatFromEulerDeg(const EulerDeg& e) {
    const float yaw = static_cast<float>(e.yaw_deg / kDegPerRad);
    const float pitch = static_cast<float>(e.pitch_deg / kDegPerRad);
    const float roll = static_cast<float>(e.roll_deg / kDegPerRad);
    const glm::quat qy = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    const glm::quat qp = glm::angleAxis(pitch, glm::vec3(1, 0, 0));
    const glm::quat qr = glm::angleAxis(roll, glm::vec3(0, 0, -1));
    return glm::normalize(qy * qp * qr);
}

EulerDeg eulerDegFromQuat(const glm::quat& q_in) {
    // R = Ry(yaw) Rx(pitch) Rz(-roll). Read the angles off the rotated axes.
    const glm::quat q = glm::normalize(q_in);
    const glm::vec3 fwd = q * glm::vec3(0, 0, -1);
    const glm::vec3 up = q * glm::vec3(0, 1, 0);
    EulerDeg e;
    const double sp = std::clamp(static_cast<double>(fwd.y), -1.0, 1.0);
    e.pitch_deg = std::asin(sp) * kDegPerRad;
    e.yaw_deg = std::atan2(-static_cast<double>(fwd.x), -static_cast<double>(fwd.z)) * kDegPerRad;
    // Roll: the angle of the rotated up vector about the forward axis, measured against the
    // up vector that yaw and pitch alone would give.
    const glm::quat qyp = quatFromEulerDeg({e.yaw_deg, e.pitch_deg, 0.0});
    const glm::vec3 up0 = qyp * glm::vec3(0, 1, 0);
    const glm::vec3 right0 = qyp * glm::vec3(1, 0, 0);
    e.roll_deg = std::atan2(static_cast<double>(glm::dot(up, right0)),
                            static_cast<double>(glm::dot(up, up0))) *
                 kDegPerRad;
    return e;
}

double angleBetweenDeg(const glm::quat& a, const glm::quat& b) {
    // In double, and through the half-angle's sine rather than the dot product's arccosine,
    // which cannot resolve angles below ~0.06° in float.
    const glm::dquat qa = glm::normalize(glm::dquat(a));
    glm::dquat qb = glm::normalize(glm::dquat(b));
    if (glm::dot(qa, qb) < 0.0)
        qb = -qb;
    const glm::dquat diff = qb - qa;
    const glm::dquat sum = qb + qa;
    const double dn = std::sqrt(glm::dot(diff, diff));
    const double sn = std::sqrt(glm::dot(sum, sum));
    return 4.0 * std::atan2(dn, sn) * kDegPerRad;
}

}  // namespace qvr
