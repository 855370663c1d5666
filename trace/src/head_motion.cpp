// Head motion from BVH (paper §5): forward kinematics to the head joint, unit and axis
// conversion, slerp resampling to the display rate, placement at a spawn point.
#include "qvr/trace/head_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "qvr/core/enum_table.h"

namespace qvr {

namespace {

// BVH characters face +z with y up; qvr looks down −z. A half turn about y maps one to the
// other and keeps handedness, so positions map (x, y, z) → (−x, y, −z) and rotations conjugate.
const glm::dquat kBvhToQvr = glm::angleAxis(3.14159265358979323846, glm::dvec3(0.0, 1.0, 0.0));

constexpr double kTypicalHeight_m = 1.75;

struct BvhUnitRow {
    BvhUnit value;
    const char* name;
    double metres;  // 0 for kAuto, which is no length
};

constexpr BvhUnitRow kBvhUnits[] = {{BvhUnit::kAuto, "auto", 0.0},
                                    {BvhUnit::kMetre, "m", 1.0},
                                    {BvhUnit::kCentimetre, "cm", 0.01},
                                    {BvhUnit::kInch, "inch", 0.0254},
                                    {BvhUnit::kCmuAsf, "cmu", 0.0254 / 0.45}};

}  // namespace

double bvhUnitMetres(BvhUnit unit) {
    const BvhUnitRow* row = enumRow(kBvhUnits, unit);
    return row != nullptr ? row->metres : 0.0;
}

const char* bvhUnitName(BvhUnit unit) {
    return enumName(kBvhUnits, unit);
}

Expected<BvhUnit> bvhUnitFromName(const std::string& name) {
    if (const auto unit = enumFromName(kBvhUnits, name))
        return *unit;
    return makeError(fmt::format("unit '{}': expected auto, m, cm, inch or cmu", name));
}

BvhUnit detectBvhUnit(const BvhMotion& motion) {
    const auto rest = bvhWorldTransforms(motion, -1);
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (size_t i = 0; i < rest.size(); ++i) {
        lo = std::min(lo, rest[i].translation.y);
        hi = std::max(hi, rest[i].translation.y);
        if (motion.joints[i].has_end_site) {
            const double y = rest[i].apply(motion.joints[i].end_site).y;
            lo = std::min(lo, y);
            hi = std::max(hi, y);
        }
    }
    const double height = hi - lo;
    BvhUnit best = BvhUnit::kCentimetre;
    double best_err = std::numeric_limits<double>::infinity();
    for (const BvhUnitRow& unit : kBvhUnits) {
        if (unit.metres <= 0.0)
            continue;
        const double err = std::fabs(std::log(height * unit.metres / kTypicalHeight_m));
        if (height > 0 && err < best_err) {
            best_err = err;
            best = unit.value;
        }
    }
    return best;
}

Expected<int> findHeadJoint(const BvhMotion& motion, const std::string& name) {
    if (motion.joints.empty())
        return makeError("BVH has no joints");
    if (!name.empty()) {
        const int j = motion.findJoint(name);
        if (j < 0)
            return makeError(fmt::format("BVH has no joint named '{}'", name));
        return j;
    }
    for (const char* n : {"Head", "head", "HEAD"}) {
        if (int j = motion.findJoint(n); j >= 0)
            return j;
    }
    // No head by name: the top of the spine chain, i.e. the highest joint of the rest pose
    // (arms hang or stretch sideways in rest poses, so they are not higher).
    const auto rest = bvhWorldTransforms(motion, -1);
    int best = 0;
    for (size_t i = 1; i < rest.size(); ++i) {
        if (rest[i].translation.y > rest[static_cast<size_t>(best)].translation.y)
            best = static_cast<int>(i);
    }
    return best;
}

Expected<PoseTrace> headPosesFromBvh(const BvhMotion& motion, const HeadMotionOptions& o) {
    if (motion.frame_count < 1)
        return makeError("BVH has no frames");
    auto head = findHeadJoint(motion, o.head_joint);
    if (!head)
        return makeError(head.error());
    const BvhUnit unit = o.unit == BvhUnit::kAuto ? detectBvhUnit(motion) : o.unit;
    const double scale = bvhUnitMetres(unit);
    // The floor: the lowest joint or end site (toe tips) of the first frame; mocap puts it near
    // y = 0, but not always.
    const auto first = bvhWorldTransforms(motion, 0);
    double floor_y = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < first.size(); ++i) {
        floor_y = std::min(floor_y, first[i].translation.y);
        if (motion.joints[i].has_end_site)
            floor_y = std::min(floor_y, first[i].apply(motion.joints[i].end_site).y);
    }
    PoseTrace out;
    out.samples.reserve(static_cast<size_t>(motion.frame_count));
    const glm::dvec3 eye(o.eye_offset_m);
    for (int f = 0; f < motion.frame_count; ++f) {
        const auto world = bvhWorldTransforms(motion, f);
        const BvhTransform& h = world[static_cast<size_t>(*head)];
        glm::dvec3 p = (h.translation - glm::dvec3(0.0, floor_y, 0.0)) * scale;
        p = kBvhToQvr * p;
        const glm::dquat q = glm::normalize(kBvhToQvr * h.rotation * glm::conjugate(kBvhToQvr));
        p += q * eye;
        PoseSample s;
        s.t_ms = f * motion.frame_time_s * 1000.0;
        s.pose.orientation = glm::quat(q);
        s.pose.position_m = glm::vec3(p);
        out.samples.push_back(s);
    }
    if (o.drop_reference_frame && out.samples.size() > 2) {
        const Pose& a = out.samples[0].pose;
        const Pose& b = out.samples[1].pose;
        if (angleBetweenDeg(a.orientation, b.orientation) > 5.0 ||
            glm::length(a.position_m - b.position_m) > 0.05f) {
            out.samples.erase(out.samples.begin());
            for (auto& s : out.samples)
                s.t_ms -= motion.frame_time_s * 1000.0;
        }
    }
    if (o.smooth_sigma_ms > 0.0)
        return smoothPoses(out, o.smooth_sigma_ms);
    return out;
}

Expected<PoseTrace> headTraceFromBvh(const BvhMotion& motion, const HeadMotionOptions& o) {
    if (!(o.rate_hz >= 1.0 && o.rate_hz <= 1000.0))
        return makeError(fmt::format("rate {} Hz outside [1, 1000]", o.rate_hz));
    auto raw = headPosesFromBvh(motion, o);
    if (!raw)
        return raw;
    auto resampled = resamplePoses(*raw, o.rate_hz, o.frames);
    if (!resampled)
        return resampled;
    return placePoses(*resampled, o.origin_m, o.yaw_deg);
}

std::string defaultBvhPath() {
    return "/usr/share/assimp/models/BVH/01_01.bvh";
}

}  // namespace qvr
