#include "qvr/experiment/render_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

#include "qvr/experiment/host.h"
#include "qvr/render/camera.h"
#include "qvr/scene/scene_loader.h"

namespace qvr::experiment {

namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr int kLayers = 4;  // fovea, middle, outer, full
constexpr const char* kLayerNames[kLayers] = {"fovea", "middle", "outer", "full"};

double msSince(SteadyClock::time_point t0) {
    return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

// The middle value, or the mean of the two middle ones of an even count.
double median(std::vector<double> v) {
    if (v.empty())
        return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct LayerSamples {
    std::vector<double> render_ms, gpu_ms, readback_ms;
    uint64_t primitives = 0;
    double total_render_ms = 0.0;
    int64_t pixels = 0;
};

Pose benchHead(const Scene& scene, int frame) {
    const int f = std::max(frame, 0);
    if (scene.spawns.empty()) {
        Pose head;
        head.orientation = quatFromEulerDeg({37.0 * f, 0.0, 0.0});
        return head;
    }
    SpawnPoint s = scene.spawns[static_cast<size_t>(f) % scene.spawns.size()];
    s.yaw_deg += 37.0f * static_cast<float>(f);
    return poseFromSpawn(s);
}

RenderBenchLayer summarise(const char* name, const LayerSamples& ls) {
    RenderBenchLayer l;
    l.name = name;
    l.pixels = ls.pixels;
    l.views = ls.render_ms.size();
    l.render_ms_median = median(ls.render_ms);
    l.render_ms_min = *std::min_element(ls.render_ms.begin(), ls.render_ms.end());
    l.gpu_ms_median = median(ls.gpu_ms);
    l.readback_ms_median = median(ls.readback_ms);
    l.triangles_per_view = static_cast<double>(ls.primitives) / static_cast<double>(l.views);
    l.triangles_per_second = ls.total_render_ms > 0
                                 ? static_cast<double>(ls.primitives) / (ls.total_render_ms * 1e-3)
                                 : 0.0;
    return l;
}

Expected<RenderBenchSceneResult> benchScene(GlRenderer& gl, const BenchScene& bench,
                                            const RenderBenchPlan& plan,
                                            const LayerPlan& layers_plan) {
    const Scene& scene = bench.scene;
    RenderBenchSceneResult r;
    r.scene = scene.name;
    r.triangles = scene.triangleCount();
    r.load_ms = bench.load_ms;
    const auto t0 = SteadyClock::now();
    if (Status s = gl.upload(scene); !s)
        return makeError(s.error());
    r.upload_ms = msSince(t0);
    LayerRect full;
    full.rect = {0, 0, plan.profile.width_px, plan.profile.height_px};
    full.width_px = plan.profile.width_px;
    full.height_px = plan.profile.height_px;
    LayerSamples samples[kLayers];
    ImageRgba8 image;
    for (int f = -1; f < plan.frames; ++f) {
        const Pose head = benchHead(scene, f);
        for (Eye eye : {Eye::kLeft, Eye::kRight}) {
            const EyeLayers& layers = layers_plan.eyes[static_cast<size_t>(eye)];
            const LayerRect* rects[kLayers] = {&layers.fovea, &layers.middle, &layers.outer, &full};
            for (int k = 0; k < kLayers; ++k) {
                if (rects[k]->empty())
                    continue;
                auto st = gl.render(layerView(plan.profile, head, eye, *rects[k]), image);
                if (!st)
                    return makeError(st.error());
                if (f < 0)
                    continue;
                LayerSamples& ls = samples[k];
                ls.render_ms.push_back(st->render_ms);
                ls.gpu_ms.push_back(st->gpu_ms);
                ls.readback_ms.push_back(st->readback_ms);
                ls.primitives += st->primitives_generated;
                ls.total_render_ms += st->render_ms;
                ls.pixels = rects[k]->pixels();
            }
        }
    }
    for (int k = 0; k < kLayers; ++k) {
        if (samples[k].render_ms.empty())
            continue;
        r.layers.push_back(summarise(kLayerNames[k], samples[k]));
        if (k < 3)
            r.layers_sum_ms_per_eye += r.layers.back().render_ms_median;
    }
    r.full_ms_per_eye = median(samples[3].render_ms);
    return r;
}

}  // namespace

std::vector<std::string> defaultRenderBenchScenes() {
    std::vector<std::string> scenes = {"builtin:room"};
    if (std::filesystem::exists(SceneLoadOptions{}.openarena_dir))
        scenes.push_back("openarena:oa_dm5");
    return scenes;
}

Expected<BenchScene> loadBenchScene(const std::string& name) {
    const auto t0 = SteadyClock::now();
    auto scene = loadScene(name);
    if (!scene)
        return makeError(scene.error());
    return BenchScene{std::move(*scene), msSince(t0)};
}

Expected<RenderBenchResult> runRenderBench(const RenderBenchPlan& plan,
                                           const std::vector<BenchScene>& scenes) {
    auto gl = GlRenderer::create(plan.renderer);
    if (!gl)
        return makeError(gl.error());
    RenderBenchResult result;
    result.plan = plan;
    result.layers_plan = LayerPlanner(plan.profile).plan(plan.gaze, plan.e1_deg);
    result.renderer = (*gl)->name();
    const char* lp_threads = std::getenv("LP_NUM_THREADS");
    result.lp_threads = lp_threads ? lp_threads : "";
    result.load_average = loadAverage1();
    for (const BenchScene& scene : scenes) {
        auto r = benchScene(**gl, scene, plan, result.layers_plan);
        if (!r)
            return makeError(r.error());
        result.scenes.push_back(std::move(*r));
    }
    return result;
}

nlohmann::json renderBenchJson(const RenderBenchResult& r) {
    nlohmann::json j;
    j["profile"] = r.plan.profile.name;
    j["width_px"] = r.plan.profile.width_px;
    j["height_px"] = r.plan.profile.height_px;
    j["e1_deg"] = r.layers_plan.e1_deg;
    j["s1"] = r.layers_plan.s1;
    j["s2"] = r.layers_plan.s2;
    j["renderer"] = r.renderer;
    j["frames"] = r.plan.frames;
    j["msaa_samples"] = r.plan.renderer.msaa_samples;
    j["load_average"] = r.load_average;
    j["scenes"] = nlohmann::json::array();
    for (const RenderBenchSceneResult& s : r.scenes) {
        nlohmann::json js;
        js["scene"] = s.scene;
        js["triangles"] = s.triangles;
        js["load_ms"] = s.load_ms;
        js["upload_ms"] = s.upload_ms;
        for (const RenderBenchLayer& l : s.layers)
            js["layers"][l.name] = {{"pixels", l.pixels},
                                    {"render_ms_median", l.render_ms_median},
                                    {"render_ms_min", l.render_ms_min},
                                    {"gpu_ms_median", l.gpu_ms_median},
                                    {"readback_ms_median", l.readback_ms_median},
                                    {"triangles_per_view", l.triangles_per_view},
                                    {"triangles_per_second", l.triangles_per_second},
                                    {"views", l.views}};
        js["layers_sum_ms_per_eye"] = s.layers_sum_ms_per_eye;
        js["full_ms_per_eye"] = s.full_ms_per_eye;
        j["scenes"].push_back(js);
    }
    return j;
}

std::string renderBenchText(const RenderBenchResult& r) {
    const HmdProfile& p = r.plan.profile;
    std::string out = fmt::format(
        "render benchmark: {} ({}x{} per eye), e1 {:.1f} s1 {:.2f} s2 {:.2f}; {}; "
        "{} sample(s) per pixel; LP_NUM_THREADS {}; load average {:.2f}\n",
        p.name, p.width_px, p.height_px, r.layers_plan.e1_deg, r.layers_plan.s1, r.layers_plan.s2,
        r.renderer, r.plan.renderer.msaa_samples,
        r.lp_threads.empty() ? "unset (all cores)" : r.lp_threads, r.load_average);
    out += "ms: wall time from first command to glFinish, before read-back\n";
    for (const RenderBenchSceneResult& s : r.scenes) {
        out += fmt::format(
            "{}: {} triangles, loaded in {:.0f} ms, uploaded in {:.0f} ms; {} frames x 2 eyes\n",
            s.scene, s.triangles, s.load_ms, s.upload_ms, r.plan.frames);
        out += fmt::format("  layer   {:>11}  {:>9} {:>9} {:>9} {:>9}  {:>10}  {:>12}\n", "pixels",
                           "ms", "min ms", "gpu ms", "read ms", "tris/view", "Mtris/s");
        for (const RenderBenchLayer& l : s.layers)
            out += fmt::format(
                "  {:<6}  {:>11}  {:9.2f} {:9.2f} {:9.2f} {:9.2f}  {:10.0f}  {:12.2f}\n", l.name,
                l.pixels, l.render_ms_median, l.render_ms_min, l.gpu_ms_median,
                l.readback_ms_median, l.triangles_per_view, l.triangles_per_second * 1e-6);
        out += fmt::format(
            "  fovea + middle + outer {:.2f} ms per eye vs full frame {:.2f} ms ({:.2f}x)\n",
            s.layers_sum_ms_per_eye, s.full_ms_per_eye,
            s.layers_sum_ms_per_eye > 0 ? s.full_ms_per_eye / s.layers_sum_ms_per_eye : 0.0);
    }
    return out;
}

}  // namespace qvr::experiment
