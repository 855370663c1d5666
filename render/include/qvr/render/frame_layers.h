// One frame's layers (paper §3.2) — fovea, middle and outer per eye, each at its own resolution —
// and a full-frame reference per eye, rendered with the OpenGL renderer and handed to a sink
// (`qvr render` writes them as PNGs). A plan in, a result out, a JSON object or text from it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/camera.h"
#include "qvr/render/gl_renderer.h"

namespace qvr {

struct FrameLayersPlan {
    HmdProfile profile;
    Gaze gaze;
    double e1_deg = 15.0;
    Pose head;
    std::string pose_source = "origin";  // where the head pose came from, for the report
    CameraOptions camera;
    GlRendererOptions renderer;
};

// One rendered view: a layer of one eye ("fovea", "middle", "outer" or "full"), or a layer the
// plan leaves empty (nothing rendered).
struct FrameLayer {
    Eye eye = Eye::kLeft;
    std::string layer;
    bool empty = false;
    LayerRect rect;
    int width_px = 0;
    int height_px = 0;
    RenderStats stats;
    std::string file;  // what the sink returned
};

struct FrameLayers {
    FrameLayersPlan plan;
    LayerPlan layers_plan;
    std::string scene;
    size_t triangles = 0;
    std::string renderer;
    std::vector<FrameLayer> layers;  // left eye then right, each fovea, middle, outer, full
};

// Takes each rendered image (eye, layer name); returns where it put it, or an error.
using FrameLayerSink =
    std::function<Expected<std::string>(Eye eye, const std::string& layer, const ImageRgba8&)>;

// Uploads `scene` to a new renderer and renders the plan's layers; stops at the first error.
Expected<FrameLayers> renderFrameLayers(const Scene& scene, const FrameLayersPlan& plan,
                                        const FrameLayerSink& sink);
nlohmann::json frameLayersJson(const FrameLayers& frame);
std::string frameLayersText(const FrameLayers& frame);

}  // namespace qvr
