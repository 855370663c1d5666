// Eye cameras and layer sub-frusta: the pinhole of foveation/eye_geometry.h turned into OpenGL
// view and projection matrices.
#include "qvr/render/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace qvr {

namespace {
LayerRect fullLayer(const HmdProfile& profile) {
    LayerRect full;
    full.rect = {0, 0, profile.width_px, profile.height_px};
    full.scale = 1.0;
    full.width_px = profile.width_px;
    full.height_px = profile.height_px;
    return full;
}
}  // namespace

Pose eyePose(const Pose& head, Eye eye, double ipd_m) {
    const float half = static_cast<float>(0.5 * ipd_m) * (eye == Eye::kLeft ? -1.0f : 1.0f);
    Pose p = head;
    p.position_m = head.position_m + head.orientation * glm::vec3(half, 0.0f, 0.0f);
    return p;
}

glm::mat4 viewMatrix(const Pose& eye_pose) {
    // World → eye is the inverse of the eye's rigid transform: R^T · (x − t).
    const glm::mat4 rotation_t =
        glm::mat4_cast(glm::conjugate(glm::normalize(eye_pose.orientation)));
    return rotation_t * glm::translate(glm::mat4(1.0f), -eye_pose.position_m);
}

glm::mat4 regionProjection(const HmdProfile& profile, double x0_px, double y0_px, double x1_px,
                           double y1_px, const CameraOptions& options) {
    const double fx = profile.focalXPx();
    const double fy = profile.focalYPx();
    const double cx = 0.5 * profile.width_px;
    const double cy = 0.5 * profile.height_px;
    const double n = options.near_m;
    // Pixel (px, py) looks along ((px − cx)/fx, −(py − cy)/fy, −1): scale to the near plane.
    const double left = n * (x0_px - cx) / fx;
    const double right = n * (x1_px - cx) / fx;
    const double top = n * (cy - y0_px) / fy;
    const double bottom = n * (cy - y1_px) / fy;
    return glm::frustum(static_cast<float>(left), static_cast<float>(right),
                        static_cast<float>(bottom), static_cast<float>(top), static_cast<float>(n),
                        static_cast<float>(options.far_m));
}

RenderView layerView(const HmdProfile& profile, const Pose& head, Eye eye, const LayerRect& layer,
                     const CameraOptions& options) {
    RenderView v;
    v.width_px = layer.width_px;
    v.height_px = layer.height_px;
    v.view = viewMatrix(eyePose(head, eye, options.ipd_m));
    const double x0 = layer.rect.x0;
    const double y0 = layer.rect.y0;
    v.projection = regionProjection(profile, x0, y0, x0 + layer.width_px * layer.scale,
                                    y0 + layer.height_px * layer.scale, options);
    return v;
}

void setSkipCone(RenderView& view, const HmdProfile& profile, const Pose& head, Eye eye,
                 const Gaze& gaze, double radius_deg, const CameraOptions& options) {
    if (!(radius_deg > 0.0)) {
        view.skip_half_angle_rad = 0.0f;
        return;
    }
    const Pose ep = eyePose(head, eye, options.ipd_m);
    const glm::dvec3 g = EyeGeometry(profile).gazeDirection(gaze);
    view.skip_apex = ep.position_m;
    view.skip_axis = glm::normalize(glm::normalize(ep.orientation) * glm::vec3(g));
    view.skip_half_angle_rad = static_cast<float>(std::min(radius_deg, 89.0) * (M_PI / 180.0));
}

RenderView fullFrameView(const HmdProfile& profile, const Pose& head, Eye eye,
                         const CameraOptions& options) {
    return layerView(profile, head, eye, fullLayer(profile), options);
}

EyeView eyeViewOf(const HmdProfile& profile, const Pose& head, Eye eye, const LayerRect& layer,
                  const CameraOptions& options) {
    const Pose ep = eyePose(head, eye, options.ipd_m);
    const double fx = profile.focalXPx();
    const double fy = profile.focalYPx();
    const double cx = 0.5 * profile.width_px;
    const double cy = 0.5 * profile.height_px;
    const double x0 = layer.rect.x0;
    const double y0 = layer.rect.y0;
    EyeView v;
    v.position_m = glm::dvec3(ep.position_m);
    v.orientation = glm::dquat(glm::normalize(ep.orientation));
    v.tan_left = (cx - x0) / fx;
    v.tan_right = (x0 + layer.width_px * layer.scale - cx) / fx;
    v.tan_up = (cy - y0) / fy;
    v.tan_down = (y0 + layer.height_px * layer.scale - cy) / fy;
    v.near_m = options.near_m;
    v.far_m = options.far_m;
    return v;
}

EyeView fullFrameEyeView(const HmdProfile& profile, const Pose& head, Eye eye,
                         const CameraOptions& options) {
    return eyeViewOf(profile, head, eye, fullLayer(profile), options);
}

Pose poseFromSpawn(const SpawnPoint& spawn) {
    Pose p;
    p.orientation = quatFromEulerDeg({spawn.yaw_deg, 0.0, 0.0});
    p.position_m = spawn.position_m;
    return p;
}

FrustumPlanes frustumPlanes(const glm::mat4& m) {
    // Gribb & Hartmann: clip-space −w ≤ x,y,z ≤ w as planes on the rows of the matrix.
    const glm::vec4 r0(m[0][0], m[1][0], m[2][0], m[3][0]);
    const glm::vec4 r1(m[0][1], m[1][1], m[2][1], m[3][1]);
    const glm::vec4 r2(m[0][2], m[1][2], m[2][2], m[3][2]);
    const glm::vec4 r3(m[0][3], m[1][3], m[2][3], m[3][3]);
    return {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
}

bool boxMayBeVisible(const FrustumPlanes& planes, const Aabb& box) {
    if (!box.valid())
        return true;
    for (const glm::vec4& p : planes) {
        // The box corner farthest along the plane normal.
        const glm::vec3 c(p.x >= 0 ? box.max.x : box.min.x, p.y >= 0 ? box.max.y : box.min.y,
                          p.z >= 0 ? box.max.z : box.min.z);
        if (p.x * c.x + p.y * c.y + p.z * c.z + p.w < 0.0f)
            return false;
    }
    return true;
}

}  // namespace qvr
