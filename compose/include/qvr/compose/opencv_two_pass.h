// The external anchor: the two-pass path (compose, then timewarp) as a user would
// write it with OpenCV's cv::remap and cv::blendLinear. Bench-only; built with QVR_WITH_OPENCV.
#pragma once

#include <array>
#include <memory>

#include "qvr/compose/uca.h"
#include "qvr/core/expected.h"
#include "qvr/core/image.h"
#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr {

// True when this build has the OpenCV anchor.
bool openCvAnchorBuilt();

#if defined(QVR_COMPOSE_HAVE_OPENCV)
class OpenCvTwoPass {
public:
    OpenCvTwoPass(const HmdProfile& profile, ComposeOptions options);
    ~OpenCvTwoPass();
    OpenCvTwoPass(const OpenCvTwoPass&) = delete;
    OpenCvTwoPass& operator=(const OpenCvTwoPass&) = delete;

    // Every per-frame step is inside: layer→eye-buffer maps and blend weights for this plan,
    // the remaps and blends, the display maps for this pose, the final remap.
    Status run(const LayerFrame& frame, const Pose& display_pose, std::array<ImageRgba8, 2>& out);

private:
    struct Scratch;
    HmdProfile m_profile;
    ComposeOptions m_options;
    std::unique_ptr<Scratch> m_scratch;
};
#endif

}  // namespace qvr
