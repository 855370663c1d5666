// Head poses: orientation as a unit quaternion, position in metres. Coordinate frame: OpenGL's
// right-handed eye space, x right, y up, looking down -z.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace qvr {

struct Pose {
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
    glm::vec3 position_m{0.0f};
};

// Yaw (about +y), pitch (about +x), roll (about -z, the viewing axis) in degrees, applied as
// yaw · pitch · roll. The decomposition LIWC's motion codec and the trace files use.
struct EulerDeg {
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    double roll_deg = 0.0;
};

glm::quat quatFromEulerDeg(const EulerDeg& e);
EulerDeg eulerDegFromQuat(const glm::quat& q);

// The smallest rotation angle between two orientations, in degrees.
double angleBetweenDeg(const glm::quat& a, const glm::quat& b);

}  // namespace qvr
