// HMD profiles: defaults, TOML loading with range checks.
#include "qvr/foveation/hmd_profile.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "qvr/core/config.h"

namespace qvr {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 180.0 / kPi;
double tanDeg(double d) {
    return std::tan(d / kDegPerRad);
}
}  // namespace

double HmdProfile::focalXPx() const {
    return 0.5 * width_px / tanDeg(0.5 * fov_h_deg);
}
double HmdProfile::focalYPx() const {
    return 0.5 * height_px / tanDeg(0.5 * fov_v_deg);
}

double HmdProfile::pixelAngleDeg() const {
    const double ax = std::atan(1.0 / focalXPx()) * kDegPerRad;
    const double ay = std::atan(1.0 / focalYPx()) * kDegPerRad;
    return std::max(ax, ay);
}

double HmdProfile::scaleAt(double eccentricity_deg) const {
    return std::max(1.0, acuity.marDeg(eccentricity_deg) / pixelAngleDeg());
}

HmdProfile defaultHmdProfile() {
    return HmdProfile{};
}

HmdProfile lowResHmdProfile() {
    HmdProfile p;
    p.name = "low";
    p.width_px = 1280;
    p.height_px = 1600;
    return p;
}

Expected<HmdProfile> parseHmdProfile(std::string_view toml_text, std::string_view source_name) {
    auto table = parseTomlText(toml_text, source_name);
    if (!table)
        return makeError(table.error());
    ConfigReader r(*table, std::string(source_name));
    HmdProfile p = defaultHmdProfile();
    p.name = r.string("name", std::string(source_name));
    p.width_px = r.integer("display.width_px", p.width_px, 16, 16384);
    p.height_px = r.integer("display.height_px", p.height_px, 16, 16384);
    p.refresh_hz = r.number("display.refresh_hz", p.refresh_hz, 1.0, 1000.0);
    p.fov_h_deg = r.number("fov.horizontal_deg", p.fov_h_deg, 10.0, 170.0);
    p.fov_v_deg = r.number("fov.vertical_deg", p.fov_v_deg, 10.0, 170.0);
    p.lens.k1 = r.number("lens.k1", p.lens.k1, -1.0, 4.0);
    p.lens.k2 = r.number("lens.k2", p.lens.k2, -1.0, 4.0);
    p.lens.chroma_red_scale = r.number("lens.chroma_red_scale", p.lens.chroma_red_scale, 0.9, 1.1);
    p.lens.chroma_blue_scale =
        r.number("lens.chroma_blue_scale", p.lens.chroma_blue_scale, 0.9, 1.1);
    p.acuity.omega0_deg = r.number("acuity.omega0_deg", p.acuity.omega0_deg, 1e-4, 1.0);
    p.acuity.slope = r.number("acuity.slope", p.acuity.slope, 0.0, 1.0);
    if (auto st = r.finish(); !st)
        return makeError(st.error());
    return p;
}

Expected<HmdProfile> loadHmdProfile(const std::string& path) {
    auto text = readTextFile(path);
    if (!text)
        return makeError(text.error());
    // A file that sets no field would silently be the default profile: a wrong or truncated
    // file more likely than a wish (`default` names that profile).
    auto table = parseTomlText(*text, path);
    if (!table)
        return makeError(table.error());
    const bool sets_a_field = std::any_of(table->begin(), table->end(), [](const auto& kv) {
        const toml::table* section = kv.second.as_table();
        return kv.first.str() != "name" && (section == nullptr || !section->empty());
    });
    if (!sets_a_field)
        return makeError(fmt::format(
            "{}: the profile file sets no field ([display], [fov], [lens] or [acuity]); use "
            "'default' for the default profile",
            path));
    return parseHmdProfile(*text, path);
}

Expected<HmdProfile> hmdProfileByName(const std::string& name_or_path) {
    if (name_or_path.empty() || name_or_path == "default" || name_or_path == "1920x2160")
        return defaultHmdProfile();
    if (name_or_path == "low" || name_or_path == "1280x1600")
        return lowResHmdProfile();
    return loadHmdProfile(name_or_path);
}

namespace {

// A TOML basic string's body: quote, backslash and control characters escaped (found by
// toml_fuzz: a name holding a backslash was written raw and did not read back).
std::string tomlEscaped(const std::string& text) {
    std::string out;
    for (const char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (u < 0x20 || u == 0x7f) {
            out += fmt::format("\\u{:04X}", u);
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace

std::string hmdProfileToToml(const HmdProfile& p) {
    return fmt::format(
        "name = \"{}\"\n\n[display]\nwidth_px = {}\nheight_px = {}\nrefresh_hz = {}\n\n"
        "[fov]\nhorizontal_deg = {}\nvertical_deg = {}\n\n[lens]\nk1 = {}\nk2 = {}\n"
        "chroma_red_scale = {}\nchroma_blue_scale = {}\n\n[acuity]\nomega0_deg = {}\nslope = {}\n",
        tomlEscaped(p.name), p.width_px, p.height_px, p.refresh_hz, p.fov_h_deg, p.fov_v_deg,
        p.lens.k1, p.lens.k2, p.lens.chroma_red_scale, p.lens.chroma_blue_scale,
        p.acuity.omega0_deg, p.acuity.slope);
}

}  // namespace qvr
