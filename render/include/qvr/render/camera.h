// Stereo eye cameras and the off-axis sub-frusta of the layers of a layer plan (paper §3.2): a
// layer is the part of the eye's full pinhole projection that its pixel rectangle covers.
#pragma once

#include <array>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "qvr/core/pose.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/scene/scene.h"
#include "qvr/scene/triangle_bvh.h"

namespace qvr {

enum class Eye : int { kLeft = 0, kRight = 1 };

inline const char* eyeName(Eye eye) {
    return eye == Eye::kLeft ? "left" : "right";
}

enum class LayerKind : int { kFovea = 0, kMiddle = 1, kOuter = 2 };

inline const char* layerName(LayerKind kind) {
    constexpr const char* kNames[] = {"fovea", "middle", "outer"};
    return kNames[static_cast<int>(kind)];
}

inline const LayerRect& layerOf(const EyeLayers& layers, LayerKind kind) {
    switch (kind) {
        case LayerKind::kFovea:
            return layers.fovea;
        case LayerKind::kMiddle:
            return layers.middle;
        case LayerKind::kOuter:
            return layers.outer;
    }
    return layers.outer;
}

struct CameraOptions {
    double ipd_m = 0.064;  // interpupillary distance; each eye sits ipd/2 from the head centre
    double near_m = 0.05;  // close enough for a hand in front of the face
    double far_m = 400.0;  // beyond the largest OpenArena level's diagonal
};

// One rendering of the scene: world → eye transform, eye → clip projection, framebuffer size.
// Framebuffer row 0 is the top of the image, as in EyeGeometry.
struct RenderView {
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    int width_px = 0;
    int height_px = 0;
    // A hole: clusters lying wholly inside this cone (world space, apex at the eye) are not
    // drawn. A periphery layer uses it for the disc the compositor takes from a finer layer
    // (docs/RENDER.md "Holes"); pixels outside the cone are exactly those of a full draw.
    // skip_half_angle_rad <= 0: no hole.
    glm::vec3 skip_apex{0.0f};
    glm::vec3 skip_axis{0.0f, 0.0f, -1.0f};  // unit length
    float skip_half_angle_rad = 0.0f;

    glm::mat4 viewProjection() const { return projection * view; }
};

// The eye's pose: the head pose moved ∓ipd/2 along the head's own x axis (left eye at −x).
Pose eyePose(const Pose& head, Eye eye, double ipd_m);
glm::mat4 viewMatrix(const Pose& eye_pose);

// The off-axis projection whose image covers the full-resolution pixel region
// [x0, x1) × [y0, y1) of the eye image (pinhole with the profile's focal lengths, principal
// point at the image centre, row 0 at the top), mapped onto the whole framebuffer.
glm::mat4 regionProjection(const HmdProfile& profile, double x0_px, double y0_px, double x1_px,
                           double y1_px, const CameraOptions& options);

// A layer's view. Its framebuffer texel i covers full-resolution pixels
// [x0 + i·scale, x0 + (i+1)·scale): the grid UCA samples (compose/src/uca.cpp), which reaches
// up to one texel past rect when rect's size is not a multiple of the scale.
RenderView layerView(const HmdProfile& profile, const Pose& head, Eye eye, const LayerRect& layer,
                     const CameraOptions& options = {});
// Sets view.skip_* to the cone of half-angle radius_deg around the gaze of `eye` at `head`
// (EyeGeometry's eccentricity: the angle to the gaze direction in the eye's frame).
void setSkipCone(RenderView& view, const HmdProfile& profile, const Pose& head, Eye eye,
                 const Gaze& gaze, double radius_deg, const CameraOptions& options = {});
// The whole eye image at full resolution: the reference each layer is a piece of.
RenderView fullFrameView(const HmdProfile& profile, const Pose& head, Eye eye,
                         const CameraOptions& options = {});

// The same view in the form the scene part's CPU triangle counter takes (TriangleBvh): eye pose
// and the tangents of the four edges of the layer's texel grid, with the same near and far.
EyeView eyeViewOf(const HmdProfile& profile, const Pose& head, Eye eye, const LayerRect& layer,
                  const CameraOptions& options = {});
EyeView fullFrameEyeView(const HmdProfile& profile, const Pose& head, Eye eye,
                         const CameraOptions& options = {});

// Standing at a spawn point, looking level along its yaw.
Pose poseFromSpawn(const SpawnPoint& spawn);

// The six clip planes (a·x + b·y + c·z + d ≥ 0 inside) of a view-projection matrix.
using FrustumPlanes = std::array<glm::vec4, 6>;
FrustumPlanes frustumPlanes(const glm::mat4& view_projection);
// False only when the box lies wholly outside one plane (conservative: may keep boxes that are
// outside near a frustum corner). An invalid (empty) box is kept, as nothing is known of it.
bool boxMayBeVisible(const FrustumPlanes& planes, const Aabb& box);

}  // namespace qvr
