// Option parsers shared by several subcommands, so that `--gaze` means the same everywhere.
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "options.h"
#ifdef QVR_HAVE_NET
#include "qvr/net/host_port.h"
#endif
#include "qvr/foveation/eye_geometry.h"
#include "qvr/foveation/hmd_profile.h"

namespace qvr::cli {

// "X,Y": gaze angles in degrees right/up of the optical axis, each finite and within ±80.
inline bool parseGazeDeg(const std::string& text, Gaze& gaze) {
    double x = 0, y = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf%c", &x, &y, &tail) != 2)
        return false;
    if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(x) > 80 || std::fabs(y) > 80)
        return false;
    gaze = {x, y};
    return true;
}

// Creates the output folder up front; false (with `error`) when it cannot be.
inline bool makeOutputDir(const std::string& dir, std::string& error) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir)) {
        error = "cannot create the output folder '" + dir + "'" +
                (ec ? ": " + ec.message() : std::string());
        return false;
    }
    return true;
}

// A check that `parse` accepts the text; else "must be <what>, got '<text>'".
template <typename T>
CLI::Validator parsedBy(bool (*parse)(const std::string&, T&), const std::string& what,
                        const std::string& desc, const std::string& name) {
    return CLI::Validator(
        [parse, what](std::string& text) -> std::string {
            T value{};
            return parse(text, value) ? std::string() : "must be " + what + ", got '" + text + "'";
        },
        desc, name);
}

// The gaze of a --gaze point option, which its check has already accepted.
inline Gaze checkedGaze(const std::string& text) {
    Gaze gaze;
    parseGazeDeg(text, gaze);
    return gaze;
}

// The HMD profile of a --profile option, which its check has already loaded once.
inline HmdProfile checkedHmdProfile(const std::string& name) {
    return hmdProfileByName(name).value();
}

// A number option refused unless finite and within [lo, hi]; its default shows in the help.
template <typename T>
CLI::Option* addFinite(CLI::App* cmd, const std::string& name, T& value, const std::string& help,
                       double lo, double hi) {
    return cmd->add_option(name, value, help)->check(finiteRange(lo, hi))->capture_default_str();
}

// A whole-number option within [lo, hi]; its default shows in the help.
inline CLI::Option* addInt(CLI::App* cmd, const std::string& name, int& value,
                           const std::string& help, int lo, int hi) {
    return cmd->add_option(name, value, help)->check(CLI::Range(lo, hi))->capture_default_str();
}

// --e1: the fovea radius in degrees of eccentricity, within [0, max_deg].
inline CLI::Option* addE1Option(CLI::App* cmd, double& e1_deg, double max_deg) {
    return addFinite(cmd, "--e1", e1_deg, "Fovea radius e1 in degrees of eccentricity", 0.0,
                     max_deg);
}

// --json: print machine-readable JSON instead of text.
inline CLI::Option* addJsonFlag(CLI::App* cmd, bool& json) {
    return cmd->add_flag("--json", json, "Print machine-readable JSON");
}

// --msaa: samples per pixel of the OpenGL renderer.
inline CLI::Option* addMsaaOption(CLI::App* cmd, int& msaa) {
    return addInt(cmd, "--msaa", msaa, "Samples per pixel (1: no multisampling)", 1, 32);
}

// Prints a command's report: the JSON object with --json, else the text.
inline void printReport(bool json, const nlohmann::json& j, const std::string& text) {
    std::fputs(json ? (j.dump(2) + "\n").c_str() : text.c_str(), stdout);
}

// The SCENE argument or option every scene-loading command takes.
inline constexpr const char* kSceneHelp =
    "openarena:MAP, nexuiz:MAP, builtin:room[?objects=N], or a .bsp/.pk3/.gltf/.glb/.obj file";

}  // namespace qvr::cli
