// libFuzzer target for the BVH motion reader (trace/, docs/MOTION.md): any text parses to a
// consistent motion whose forward kinematics and head trace stay finite, or yields an error
// message. Limits are tightened so a hostile declared size fails fast instead of allocating.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "qvr/core/check.h"
#include "qvr/trace/bvh.h"
#include "qvr/trace/head_motion.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    qvr::BvhLimits limits;
    limits.max_frames = 4096;
    limits.max_values = 1 << 16;
    auto motion = qvr::parseBvh(text, "fuzz", limits);
    if (!motion.ok()) {
        QVR_CHECK(!motion.error().empty());
        return 0;
    }
    const qvr::BvhMotion& m = *motion;
    QVR_CHECK(!m.joints.empty() && m.frame_count >= 0 && m.channel_count >= 0);
    QVR_CHECK(m.values.size() ==
              static_cast<size_t>(m.frame_count) * static_cast<size_t>(m.channel_count));
    int channels = 0;
    for (size_t j = 0; j < m.joints.size(); ++j) {
        const qvr::BvhJoint& joint = m.joints[j];
        QVR_CHECK(joint.parent < static_cast<int>(j));  // parents before children
        QVR_CHECK(joint.first_channel == channels);
        channels += static_cast<int>(joint.channels.size());
    }
    QVR_CHECK(channels == m.channel_count);
    QVR_CHECK(m.findJoint(m.joints[0].name) >= 0);

    // Forward kinematics on the rest pose and on the first and last frames.
    for (int f : {-1, 0, m.frame_count - 1}) {
        if (f >= m.frame_count)
            continue;
        const auto world = qvr::bvhWorldTransforms(m, f);
        QVR_CHECK(world.size() == m.joints.size());
    }
    // The path `qvr trace motion` takes: head joint, units, resampling to the display rate.
    qvr::HeadMotionOptions options;
    options.frames = 64;
    options.smooth_sigma_ms = (size & 1) ? 10.0 : 0.0;
    auto trace = qvr::headTraceFromBvh(m, options);
    if (!trace.ok())
        QVR_CHECK(!trace.error().empty());
    return 0;
}
