// The shared option declarations and their checks (options.h).
#include "options.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include <fmt/format.h>

#include "cli_parse.h"
#include "qvr/core/cpu_cores.h"
#include "qvr/foveation/hmd_profile.h"

#ifdef QVR_HAVE_RUNTIME
#include "qvr/codec/video_codec.h"
#include "qvr/net/link_emulator.h"
#include "qvr/runtime/session.h"
#endif

namespace qvr::cli {

namespace fs = std::filesystem;

namespace {

// The whole of `text` as a double; false when it is not a number at all.
bool parseDouble(const std::string& text, double& value) {
    if (text.empty())
        return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size();
}

// Refuses text that is not a finite number within `in_range`; `what` says what it must be.
CLI::Validator finiteCheck(std::function<bool(double)> in_range, const std::string& what,
                           const std::string& desc, const std::string& name) {
    return CLI::Validator(
        [in_range, what](std::string& text) -> std::string {
            double v = 0;
            if (!parseDouble(text, v) || !std::isfinite(v) || !in_range(v))
                return fmt::format("must be {}, got '{}'", what, text);
            return {};
        },
        desc, name);
}

}  // namespace

CLI::Validator finiteRange(double lo, double hi) {
    return finiteCheck([lo, hi](double v) { return v >= lo && v <= hi; },
                       fmt::format("a finite number in [{}, {}]", lo, hi),
                       fmt::format("FINITE in [{} - {}]", lo, hi), "FINITE_RANGE");
}

CLI::Validator finiteNumber() {
    return finiteCheck([](double) { return true; }, "a finite number", "FINITE", "FINITE");
}

CLI::Validator unsignedInteger() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
                return fmt::format("must be a whole number from 0 up, got '{}'", text);
            return {};
        },
        "", "UINT");
}

CLI::Validator readableFile() {
    return CLI::Validator(
        [](std::string& path) -> std::string {
            struct stat st {};
            if (::stat(path.c_str(), &st) != 0)
                return fmt::format("'{}' does not exist", path);
            if (S_ISDIR(st.st_mode))
                return fmt::format("'{}' is a directory, not a file", path);
            if (!S_ISREG(st.st_mode))
                return fmt::format("'{}' is not a regular file (a FIFO, socket or device)", path);
            if (::access(path.c_str(), R_OK) != 0)
                return fmt::format("'{}' cannot be read", path);
            return {};
        },
        "FILE", "READABLE_FILE");
}

std::string outputFolderError(const std::string& dir) {
    std::error_code ec;
    fs::path p = dir.empty() ? fs::path(".") : fs::path(dir);
    // The nearest part of the path that exists decides: the rest is made under it.
    while (!fs::exists(p, ec)) {
        if (!p.has_parent_path() || p.parent_path() == p) {
            p = ".";
            break;
        }
        p = p.parent_path();
    }
    if (!fs::is_directory(p, ec))
        return fmt::format("cannot make the folder '{}': '{}' is not a directory", dir, p.string());
    if (::access(p.c_str(), W_OK | X_OK) != 0)
        return fmt::format("cannot write in '{}'", p.string());
    return {};
}

std::string writableFileError(const std::string& path, bool make_folder) {
    if (path.empty())
        return "an empty path";
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return fmt::format("'{}' is a directory", path);
        if (!S_ISREG(st.st_mode) && !S_ISCHR(st.st_mode))
            return fmt::format("'{}' is not a regular file (a FIFO or socket)", path);
        if (::access(path.c_str(), W_OK) != 0)
            return fmt::format("cannot write '{}'", path);
        return {};
    }
    const fs::path parent = fs::path(path).parent_path();
    const std::string folder = parent.empty() ? "." : parent.string();
    if (make_folder)
        return outputFolderError(folder);
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        return fmt::format("cannot write '{}': its folder '{}' does not exist", path, folder);
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        return fmt::format("cannot write '{}': its folder '{}' is not writable", path, folder);
    return {};
}

CLI::Validator writableFile() {
    return CLI::Validator([](std::string& path) { return writableFileError(path, false); }, "FILE",
                          "WRITABLE_FILE");
}

CLI::Validator writableFileMakingFolder() {
    return CLI::Validator([](std::string& path) { return writableFileError(path, true); }, "FILE",
                          "WRITABLE_FILE");
}

CLI::Validator outputFolder() {
    return CLI::Validator([](std::string& dir) { return outputFolderError(dir); }, "DIR",
                          "OUTPUT_FOLDER");
}

CLI::Option* addProfileOption(CLI::App* cmd, std::string& profile, ProfileNames names) {
    const bool with_runtime = names == ProfileNames::kRuntime;
    const std::string help =
        fmt::format("Display profile: default (1920x2160), low (1280x1600){} or a TOML file",
                    with_runtime ? ", run (480x540), small (320x360)" : "");
    return cmd->add_option("--profile", profile, help)
        ->check(explainedBy(
            [with_runtime](const std::string& name) {
#ifdef QVR_HAVE_RUNTIME
                return with_runtime ? runtime::runtimeProfileByName(name) : hmdProfileByName(name);
#else
                (void)with_runtime;
                return hmdProfileByName(name);
#endif
            },
            "PROFILE", "PROFILE"))
        ->capture_default_str();
}

CLI::Option* addFramesOption(CLI::App* cmd, int& frames, int min_frames, int max_frames,
                             const std::string& help) {
    return addInt(cmd, "--frames", frames, help, min_frames, max_frames);
}

CLI::Option* addGazePointOption(CLI::App* cmd, std::string& gaze) {
    return cmd
        ->add_option("--gaze", gaze,
                     "Gaze point X,Y in degrees right/up of the optical axis (each within ±80)")
        ->check(parsedBy(&parseGazeDeg, "X,Y in degrees within ±80", "X,Y", "GAZE_POINT"))
        ->capture_default_str();
}

CLI::Option* addGazeSourceOption(CLI::App* cmd, std::string& gaze) {
    return cmd->add_option("--gaze", gaze, "Gaze: model (seeded by --seed), center, or a gaze CSV")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                if (text == "model" || text == "center")
                    return {};
                std::string why = readableFile()(text);
                return why.empty() ? why : "not model, center or a gaze CSV: " + why;
            },
            "model|center|CSV", "GAZE_SOURCE"))
        ->capture_default_str();
}

CLI::Option* addSeedOption(CLI::App* cmd, uint64_t& seed, const std::string& help,
                           const std::string& name) {
    return cmd->add_option(name, seed, help)->check(unsignedInteger())->capture_default_str();
}

CLI::Option* addCoreOption(CLI::App* cmd, int& core, const std::string& help) {
    return cmd->add_option("--core", core, help)
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                if (text == "-1")
                    return {};
                const std::vector<int> cores = allowedCores();
                const bool digits = !text.empty() && text.size() < 7 &&
                                    text.find_first_not_of("0123456789") == std::string::npos;
                const int c = digits ? std::stoi(text) : -2;
                if (std::find(cores.begin(), cores.end(), c) != cores.end())
                    return {};
                return fmt::format(
                    "must be -1 (no pinning) or a core this process may run on "
                    "({}), got '{}'",
                    describeCores(cores), text);
            },
            "CORE", "CORE"))
        ->capture_default_str();
}

CLI::Option* addHardwareOption(CLI::App* cmd, std::string& hardware, const std::string& help) {
    return cmd->add_option("--hardware", hardware, help)->check(readableFile());
}

CLI::Option* addOutputFolderOption(CLI::App* cmd, std::string& out, const std::string& help) {
    return cmd->add_option("--out", out, help)->check(outputFolder())->capture_default_str();
}

CLI::Option* addOutputFileOption(CLI::App* cmd, std::string& out, const std::string& help) {
    return cmd->add_option("--out", out, help)->required()->check(writableFile());
}

CLI::Option* addMotionOption(CLI::App* cmd, std::string& motion) {
    return cmd
        ->add_option("--motion", motion,
                     "Head motion: default (CMU BVH), a .bvh, a pose CSV, still")
        ->capture_default_str();
}

CLI::Option* addLodOption(CLI::App* cmd, float& lod_px) {
    return addFinite(cmd, "--lod-px", lod_px,
                     "Level of detail: largest vertex move in each view's own pixels (0: full "
                     "detail)",
                     0.0, 16.0);
}

#ifdef QVR_HAVE_RUNTIME
void addKeyOptions(CLI::App* cmd, std::string& key, std::string& key_file) {
    cmd->add_option("--key", key, "Pre-shared key: 64 hex digits, or pass:TEXT");
    cmd->add_option("--key-file", key_file, "File holding the pre-shared key")
        ->check(readableFile());
}

CLI::Option* addCodecOption(CLI::App* cmd, std::string& codec) {
    return cmd
        ->add_option("--codec", codec,
                     "Codec backend: x264 or raw (a client's must match its server's)")
        ->check(explainedBy(
            [](const std::string& backend) {
                CodecConfig config;
                config.backend = backend;
                return validateCodecConfig(config);
            },
            "x264|raw", "CODEC"))
        ->capture_default_str();
}

CLI::Option* addLinkOption(CLI::App* cmd, std::string& net) {
    return cmd
        ->add_option("--net", net,
                     "Link spec for net's emulator: none, wifi, lte, 5g, rate:MBPS, trace:FILE, "
                     "with impairments after commas (core/link_spec.h)")
        ->check(explainedBy([](const std::string& spec) { return qvr::loadLinkSpec(spec); }, "LINK",
                            "LINK"))
        ->capture_default_str();
}

void addPeripheryPassFlags(CLI::App* cmd, bool& one_pass_periphery, bool& no_holes) {
    cmd->add_flag("--one-pass-periphery", one_pass_periphery,
                  "Server renders middle and outer in one geometry pass per eye (pays when "
                  "vertex-bound: no LOD, small displays)");
    cmd->add_flag("--no-holes", no_holes,
                  "Server draws every periphery layer whole, also where the headset's fovea (or "
                  "the middle layer) covers it");
}

CLI::Option* addSharePeripheryOption(CLI::App* cmd, std::string& mode) {
    return cmd
        ->add_option("--share-periphery", mode,
                     "Server shares one outer layer among headsets of close pose, one middle "
                     "layer among those of close gaze too: off, auto (while its SSIM by "
                     "eccentricity band holds) or on (docs/RUNTIME.md)")
        ->check(CLI::IsMember({"off", "auto", "on"}))
        ->capture_default_str();
}
#endif

}  // namespace qvr::cli
