// `qvr plan`: print the layer plan (paper §3.1, Eq. 1) for a gaze point and a fovea radius.
#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "qvr/foveation/layer_plan.h"

namespace qvr::cli {

namespace {

struct PlanOptions {
    double e1_deg = 15.0;
    std::string gaze = "0,0";
    std::string profile = "default";
    bool json = false;
};

nlohmann::json rectJson(const LayerRect& l) {
    return {{"x0", l.rect.x0},          {"y0", l.rect.y0},     {"x1", l.rect.x1},
            {"y1", l.rect.y1},          {"scale", l.scale},    {"width_px", l.width_px},
            {"height_px", l.height_px}, {"pixels", l.pixels()}};
}

}  // namespace

nlohmann::json planJson(const LayerPlan& p, const HmdProfile& profile) {
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
        eyes.push_back({{"fovea", rectJson(e.fovea)},
                        {"middle", rectJson(e.middle)},
                        {"outer", rectJson(e.outer)}});
    }
    j["eyes"] = eyes;
    return j;
}

static Registered registerPlan(CLI::App& app) {
    auto opts = std::make_shared<PlanOptions>();
    CLI::App* cmd = app.add_subcommand("plan", "Print the layer plan (Eq. 1) for a fovea radius");
    cmd->add_option("--e1", opts->e1_deg, "Fovea radius e1 in degrees of eccentricity")
        ->check(finiteRange(0.0, 180.0))
        ->capture_default_str();
    addGazePointOption(cmd, opts->gaze);
    addProfileOption(cmd, opts->profile);
    cmd->add_flag("--json", opts->json, "Print machine-readable JSON");
    Action action = [opts]() -> int {
        Gaze gaze;
        parseGazeDeg(opts->gaze, gaze);  // checked when parsed
        auto profile = hmdProfileByName(opts->profile);
        if (!profile) {
            std::fprintf(stderr, "qvr plan: %s\n", profile.error().c_str());
            return 2;
        }
        const LayerPlanner planner(*profile);
        const LayerPlan p = planner.plan(gaze, opts->e1_deg);
        if (opts->json) {
            std::printf("%s\n", planJson(p, *profile).dump(2).c_str());
            return 0;
        }
        fmt::print("profile {} ({}x{} per eye, {}x{} deg, omega* {:.4f} deg/px)\n", profile->name,
                   profile->width_px, profile->height_px, profile->fov_h_deg, profile->fov_v_deg,
                   profile->pixelAngleDeg());
        fmt::print("gaze ({:.1f}, {:.1f}) deg   e1 {:.2f}  e2* {:.2f}  s1 {:.2f}  s2 {:.2f}\n",
                   gaze.x_deg, gaze.y_deg, p.e1_deg, p.e2_deg, p.s1, p.s2);
        const auto& e = p.eyes[0];
        auto row = [](const char* name, const LayerRect& l) {
            fmt::print(
                "  {:<7} rect [{:4},{:4})x[{:4},{:4})  scale {:6.2f}  {:5}x{:<5} = {:9} px\n", name,
                l.rect.x0, l.rect.x1, l.rect.y0, l.rect.y1, l.scale, l.width_px, l.height_px,
                l.pixels());
        };
        row("fovea", e.fovea);
        row("middle", e.middle);
        row("outer", e.outer);
        fmt::print("  full frame {} px per eye; fovea {:.1f}%, remote {:.2f}% of it\n",
                   p.full_pixels, 100.0 * p.fovea_fraction,
                   100.0 * static_cast<double>(p.remotePixels()) / p.full_pixels);
        return 0;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(20, registerPlan);

}  // namespace qvr::cli
