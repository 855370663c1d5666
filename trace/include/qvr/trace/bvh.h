// BVH motion capture (HIERARCHY/MOTION text) read as untrusted input, and forward kinematics
// over its joint hierarchy: the source of real head motion for the workloads (paper §5).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "qvr/core/expected.h"

namespace qvr {

enum class BvhChannel : uint8_t { kXpos, kYpos, kZpos, kXrot, kYrot, kZrot };

struct BvhJoint {
    std::string name;  // "End Site" joints are kept as end_site children, not joints
    int parent = -1;   // index into BvhSkeleton::joints; -1 for the root
    glm::dvec3 offset{0.0};
    std::vector<BvhChannel> channels;  // in file order; rotations compose in this order
    int first_channel = 0;             // column of channels[0] in a motion frame
    bool has_end_site = false;
    glm::dvec3 end_site{0.0};
};

struct BvhMotion {
    std::vector<BvhJoint> joints;  // parents before children (file order)
    int channel_count = 0;         // values per frame
    int frame_count = 0;
    double frame_time_s = 0.0;
    std::vector<double> values;  // frame_count × channel_count, row-major
    int ignored_frames = 0;      // whole frames found after the declared count (≤ 16)

    const double* frame(int f) const {
        return values.data() + static_cast<size_t>(f) * static_cast<size_t>(channel_count);
    }
    int findJoint(std::string_view name) const;  // exact name, -1 if absent
};

// Bounds on what a file may declare, so a hostile file cannot make the reader allocate without
// limit (STYLE.md §6). Real CMU files: 31 joints, 96 channels, a few thousand frames.
struct BvhLimits {
    size_t max_bytes = size_t{64} << 20;
    int max_joints = 512;
    int max_depth = 64;
    int max_frames = 1'000'000;
    int64_t max_values = int64_t{64} << 20;  // frames × channels
    size_t max_name_chars = 128;
    double max_abs_value = 1e7;
};

// Parses BVH text. Errors name the line: "name:LINE: what".
Expected<BvhMotion> parseBvh(std::string_view text, std::string_view source_name = "bvh",
                             const BvhLimits& limits = {});
Expected<BvhMotion> loadBvhFile(const std::string& path, const BvhLimits& limits = {});

// A rigid transform in the file's units and axes.
struct BvhTransform {
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
    glm::dvec3 translation{0.0};
    glm::dvec3 apply(const glm::dvec3& p) const { return rotation * p + translation; }
};

// World transform of every joint at frame f (f = -1: the rest pose, all channels zero). BVH
// semantics: local = translate(offset + position channels) · rotations in channel order.
std::vector<BvhTransform> bvhWorldTransforms(const BvhMotion& motion, int frame);

}  // namespace qvr
