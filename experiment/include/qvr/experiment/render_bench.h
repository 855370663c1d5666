// `qvr bench render`: milliseconds per layer (fovea, middle, outer, and the full frame they
// replace) and triangles per second of the OpenGL renderer (paper §3.2), per scene. A plan in,
// a result out, a JSON object or text from the result.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/foveation/layer_plan.h"
#include "qvr/render/gl_renderer.h"
#include "qvr/scene/scene.h"

namespace qvr::experiment {

struct RenderBenchPlan {
    HmdProfile profile;
    Gaze gaze;
    double e1_deg = 15.0;
    int frames = 5;  // timed frames per scene, after one warm-up frame
    GlRendererOptions renderer;
};

// A scene to benchmark and how long loading it took.
struct BenchScene {
    Scene scene;
    double load_ms = 0.0;
};

// The scenes benchmarked when none is named: builtin:room, and openarena:oa_dm5 when installed.
std::vector<std::string> defaultRenderBenchScenes();
Expected<BenchScene> loadBenchScene(const std::string& name);

struct RenderBenchLayer {
    std::string name;  // fovea, middle, outer or full
    int64_t pixels = 0;
    double render_ms_median = 0.0;
    double render_ms_min = 0.0;  // under contention for the cores, the steadier estimate
    double gpu_ms_median = 0.0;
    double readback_ms_median = 0.0;
    double triangles_per_view = 0.0;
    double triangles_per_second = 0.0;
    size_t views = 0;
};

struct RenderBenchSceneResult {
    std::string scene;
    size_t triangles = 0;
    double load_ms = 0.0;
    double upload_ms = 0.0;
    std::vector<RenderBenchLayer> layers;  // the non-empty ones, fovea to full
    double layers_sum_ms_per_eye = 0.0;    // fovea + middle + outer medians
    double full_ms_per_eye = 0.0;
};

struct RenderBenchResult {
    RenderBenchPlan plan;
    LayerPlan layers_plan;
    std::string renderer;
    std::string lp_threads;  // LP_NUM_THREADS, empty when unset
    double load_average = 0.0;
    std::vector<RenderBenchSceneResult> scenes;
};

// Renders each scene: a warm-up frame (llvmpipe compiles its shader variants on first use), then
// plan.frames frames from the spawn points, turning 37° each frame so views differ.
Expected<RenderBenchResult> runRenderBench(const RenderBenchPlan& plan,
                                           const std::vector<BenchScene>& scenes);
nlohmann::json renderBenchJson(const RenderBenchResult& result);
std::string renderBenchText(const RenderBenchResult& result);

}  // namespace qvr::experiment
