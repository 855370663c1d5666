// Head motion from motion capture (paper §5): the head joint's world pose through the BVH
// hierarchy, converted to metres and qvr's y-up −z-forward frame, resampled to the display rate.
#pragma once

#include <string>

#include <glm/vec3.hpp>

#include "qvr/trace/bvh.h"
#include "qvr/trace/pose_trace.h"

namespace qvr {

// Length unit of a BVH file. CMU's cgspeed conversions use the ASF unit of 1/0.45 inch
// (0.05644 m); other exporters use centimetres, inches or metres. kAuto picks the unit that
// makes the rest-pose skeleton closest to 1.75 m tall (docs/MOTION.md).
enum class BvhUnit { kAuto, kMetre, kCentimetre, kInch, kCmuAsf };

double bvhUnitMetres(BvhUnit unit);
const char* bvhUnitName(BvhUnit unit);
Expected<BvhUnit> bvhUnitFromName(const std::string& name);
// The unit kAuto resolves to for this skeleton.
BvhUnit detectBvhUnit(const BvhMotion& motion);

struct HeadMotionOptions {
    BvhUnit unit = BvhUnit::kAuto;
    std::string head_joint;  // empty: "Head"/"head", else the highest joint of the rest pose
    // Eye midpoint relative to the head joint, in the head's frame (x right, y up, −z forward),
    // metres: the head joint of mocap skeletons sits at the base of the skull.
    glm::vec3 eye_offset_m{0.0f, 0.08f, -0.08f};
    // CMU's BVH conversions start with a reference pose (arms out, head level) before the
    // motion: a first frame that jumps more than 5° or 5 cm to the second is dropped.
    bool drop_reference_frame = true;
    // Gaussian smoothing of the head pose in time (sigma, ms); 0 = off. Mocap head markers
    // jitter (01_03 of assimp-testmodels: median 115°/s frame to frame); ~10 ms removes that.
    double smooth_sigma_ms = 0.0;
    double rate_hz = 90.0;     // display rate to resample to
    int frames = 0;            // 0: as many as the recording holds
    glm::vec3 origin_m{0.0f};  // where the head starts, at floor level (y = floor height)
    double yaw_deg = 0.0;      // which way the head looks at the start
};

// The head joint's index under the options' rule, or an error naming the candidates.
Expected<int> findHeadJoint(const BvhMotion& motion, const std::string& name);

// The head (eye-midpoint) pose of every BVH frame, in metres and qvr axes, the floor (lowest
// joint of the first frame) at y = 0, time from 0 at the file's frame rate. Not yet placed.
Expected<PoseTrace> headPosesFromBvh(const BvhMotion& motion, const HeadMotionOptions& options);

// headPosesFromBvh, resampled to options.rate_hz and placed at origin/yaw.
Expected<PoseTrace> headTraceFromBvh(const BvhMotion& motion, const HeadMotionOptions& options);

// The recording `qvr trace motion --default` uses (from Debian's assimp-testmodels).
std::string defaultBvhPath();

}  // namespace qvr
