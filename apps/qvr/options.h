// Options shared by several subcommands, each declared once here (name, help, check), and the
// CLI11 validators every declaration uses. A value a check refuses is a parse error: main.cpp
// prints CLI11's message (the option's name and why) and exits 2 before the command starts.
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

namespace qvr::cli {

// The longest run a duration option accepts: one year, in seconds.
inline constexpr double kMaxDurationS = 365.0 * 24 * 3600;

// --- checks ----------------------------------------------------------------------------------

// A finite number within [lo, hi]. CLI::Range lets NaN through (every comparison with NaN is
// false) and a range with an infinite end lets infinities through; this refuses both.
CLI::Validator finiteRange(double lo, double hi);
// Any finite number (no NaN, no infinity).
CLI::Validator finiteNumber();
// A whole number written without a sign: unsigned parsing would wrap "-1" to 2^64-1.
CLI::Validator unsignedInteger();
// A file that exists, is a regular file and can be read: refused before it is opened, so a FIFO
// or a device cannot block the command and a directory is not read as an empty file.
CLI::Validator readableFile();
// A file the command writes: not a directory, FIFO or socket, and in a folder that exists and
// can be written (the file itself is not created by the check).
CLI::Validator writableFile();
// As writableFile, for a command that makes the file's folder itself: the folder may be missing
// when it can be made.
CLI::Validator writableFileMakingFolder();
// A folder the command writes into: one that exists and can be written, or can be made.
CLI::Validator outputFolder();

// Why `dir` cannot be an output folder (empty when it can): it, or the nearest part of it that
// exists, must be a writable directory.
std::string outputFolderError(const std::string& dir);
// Why `path` cannot be written as an output file (empty when it can); see writableFile.
std::string writableFileError(const std::string& path, bool make_folder);

// A check from a parser that says why it refuses: `parse(text)` returns an Expected or a Status,
// whose error is the message.
template <typename Parse>
CLI::Validator explainedBy(Parse parse, const std::string& desc, const std::string& name) {
    return CLI::Validator(
        [parse](std::string& text) -> std::string {
            const auto parsed = parse(text);
            return parsed ? std::string() : parsed.error();
        },
        desc, name);
}

// --- shared options --------------------------------------------------------------------------

// Which display profiles a command knows: the HMD profiles of the paper, or also the small
// ones of the runtime (`run` 480x540, `small` 320x360).
enum class ProfileNames { kHmd, kRuntime };

// --profile: a profile name or a TOML file, loaded by the check (a bad or empty file is refused
// at parse time).
CLI::Option* addProfileOption(CLI::App* cmd, std::string& profile,
                              ProfileNames names = ProfileNames::kHmd);
// --frames within [min_frames, max_frames].
CLI::Option* addFramesOption(CLI::App* cmd, int& frames, int min_frames, int max_frames,
                             const std::string& help);
// --gaze as a point: "X,Y" degrees right/up of the optical axis, each within ±80.
CLI::Option* addGazePointOption(CLI::App* cmd, std::string& gaze);
// --gaze as a source of samples: model (seeded), center, or a gaze CSV file.
CLI::Option* addGazeSourceOption(CLI::App* cmd, std::string& gaze);
// --seed (or another name): an unsigned 64-bit seed.
CLI::Option* addSeedOption(CLI::App* cmd, uint64_t& seed, const std::string& help,
                           const std::string& name = "--seed");
// --core: -1 (no pinning) or a core this process may run on.
CLI::Option* addCoreOption(CLI::App* cmd, int& core, const std::string& help);
// The help of --hardware where the file overrides the simulator's modelled constants.
inline constexpr const char* kHardwareOverrideHelp =
    "TOML file overriding the modelled hardware's constants (docs/MODEL.md)";
// --hardware: a hardware file (sim/hardware.h) to read; `help` says what the command takes it for.
CLI::Option* addHardwareOption(CLI::App* cmd, std::string& hardware, const std::string& help);
// --out as the folder the command writes into, checked before the work starts.
CLI::Option* addOutputFolderOption(CLI::App* cmd, std::string& out, const std::string& help);
// --out as the one file the command writes (required), checked before the work starts.
CLI::Option* addOutputFileOption(CLI::App* cmd, std::string& out, const std::string& help);
// --motion: a head motion for the runtime (default, a .bvh, a pose CSV, still).
CLI::Option* addMotionOption(CLI::App* cmd, std::string& motion);
// --lod-px (render/draw_list.h): each view draws every scene cluster at the coarsest level of
// detail whose vertices move at most this many of the view's own pixels; 0 draws full detail.
CLI::Option* addLodOption(CLI::App* cmd, float& lod_px);

#ifdef QVR_HAVE_RUNTIME
// --key and --key-file: the pre-shared key, exactly one of them (checked by the command).
void addKeyOptions(CLI::App* cmd, std::string& key, std::string& key_file);
// --codec: a codec backend (x264 or raw).
CLI::Option* addCodecOption(CLI::App* cmd, std::string& codec);
// --net: a link spec for net's emulator (net/link_emulator.h's grammar).
CLI::Option* addLinkOption(CLI::App* cmd, std::string& net);
// --one-pass-periphery and --no-holes: how the render server draws the periphery layers.
void addPeripheryPassFlags(CLI::App* cmd, bool& one_pass_periphery, bool& no_holes);
// --share-periphery off|auto|on: one outer layer for headsets of close pose (docs/RUNTIME.md).
CLI::Option* addSharePeripheryOption(CLI::App* cmd, std::string& mode);
#endif

}  // namespace qvr::cli
