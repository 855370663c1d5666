#include "qvr/foveation/layer_plan_report.h"

#include <fmt/format.h>

namespace qvr {

nlohmann::json layerRectJson(const LayerRect& l) {
    return {{"x0", l.rect.x0},          {"y0", l.rect.y0},     {"x1", l.rect.x1},
            {"y1", l.rect.y1},          {"scale", l.scale},    {"width_px", l.width_px},
            {"height_px", l.height_px}, {"pixels", l.pixels()}};
}

nlohmann::json layerPlanJson(const LayerPlan& p, const HmdProfile& profile) {
    nlohmann::json j;
    j["profile"] = profile.name;
    j["gaze_deg"] = {p.gaze.x_deg, p.gaze.y_deg};
    j["e1_deg"] = p.e1_deg;
    j["e2_deg"] = p.e2_deg;
    j["s1"] = p.s1;
    j["s2"] = p.s2;
    j["cover_deg"] = p.cover_deg;
    j["pixel_angle_deg"] = profile.pixelAngleDeg();
    j["pixels"] = {{"fovea", p.fovea_pixels},
                   {"middle", p.middle_pixels},
                   {"outer", p.outer_pixels},
                   {"full", p.full_pixels}};
    j["pixels_note"] = "per eye; fovea at full resolution, middle and outer at s1 and s2";
    j["fovea_fraction"] = p.fovea_fraction;
    j["remote_fraction"] =
        static_cast<double>(p.remotePixels()) / static_cast<double>(p.full_pixels);
    j["has_remote"] = p.hasRemote();
    nlohmann::json eyes = nlohmann::json::array();
    for (const auto& e : p.eyes) {
        eyes.push_back({{"fovea", layerRectJson(e.fovea)},
                        {"middle", layerRectJson(e.middle)},
                        {"outer", layerRectJson(e.outer)}});
    }
    j["eyes"] = eyes;
    return j;
}

std::string layerPlanText(const LayerPlan& p, const HmdProfile& profile) {
    std::string out = fmt::format("profile {} ({}x{} per eye, {}x{} deg, omega* {:.4f} deg/px)\n",
                                  profile.name, profile.width_px, profile.height_px,
                                  profile.fov_h_deg, profile.fov_v_deg, profile.pixelAngleDeg());
    out += fmt::format("gaze ({:.1f}, {:.1f}) deg   e1 {:.2f}  e2* {:.2f}  s1 {:.2f}  s2 {:.2f}\n",
                       p.gaze.x_deg, p.gaze.y_deg, p.e1_deg, p.e2_deg, p.s1, p.s2);
    const auto& e = p.eyes[0];
    auto row = [&out](const char* name, const LayerRect& l) {
        out += fmt::format(
            "  {:<7} rect [{:4},{:4})x[{:4},{:4})  scale {:6.2f}  {:5}x{:<5} = {:9} px\n", name,
            l.rect.x0, l.rect.x1, l.rect.y0, l.rect.y1, l.scale, l.width_px, l.height_px,
            l.pixels());
    };
    row("fovea", e.fovea);
    row("middle", e.middle);
    row("outer", e.outer);
    out += fmt::format("  full frame {} px per eye; fovea {:.1f}%, remote {:.2f}% of it\n",
                       p.full_pixels, 100.0 * p.fovea_fraction,
                       100.0 * static_cast<double>(p.remotePixels()) / p.full_pixels);
    return out;
}

}  // namespace qvr
