// `qvr trace motion|gaze`: head-motion traces from BVH motion capture and seeded gaze traces
// (paper §5 workloads; §7 120 Hz eye trackers), written as the CSV formats of docs/MOTION.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "bench_commands.h"
#include "cli_parse.h"
#include "qvr/trace/trace_summary.h"

namespace qvr::cli {

namespace {

bool parseTriple(const std::string& text, glm::vec3& out) {
    double x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3)
        return false;
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) ||
        std::max({std::fabs(x), std::fabs(y), std::fabs(z)}) > 1e5)
        return false;
    out = glm::vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    return true;
}

struct MotionOptions {
    std::string bvh;
    bool use_default = false;
    std::string out;
    std::string unit = "auto";
    std::string origin = "0,0,0";
    bool keep_first = false;
    HeadMotionOptions head;
};

int runTraceMotion(const MotionOptions& o) {
    constexpr const char* kCmd = "qvr trace motion";
    if (o.bvh.empty() && !o.use_default) {
        std::fprintf(stderr, "%s: give --bvh FILE or --default\n", kCmd);
        return 2;
    }
    const std::string path = o.use_default ? defaultBvhPath() : o.bvh;
    HeadMotionOptions h = o.head;
    auto unit = bvhUnitFromName(o.unit);
    if (!unit) {
        std::fprintf(stderr, "%s: --unit: %s\n", kCmd, unit.error().c_str());
        return 2;
    }
    h.unit = *unit;
    parseTriple(o.origin, h.origin_m);  // checked when parsed
    h.drop_reference_frame = !o.keep_first;
    auto motion = loadBvhFile(path);
    if (!motion) {
        std::fprintf(stderr, "%s: %s%s\n", kCmd, motion.error().c_str(),
                     o.use_default ? " (install the Debian package assimp-testmodels)" : "");
        return 2;
    }
    auto trace = headTraceFromBvh(*motion, h);
    if (!trace) {
        std::fprintf(stderr, "%s: %s: %s\n", kCmd, path.c_str(), trace.error().c_str());
        return 2;
    }
    if (Status s = writePoseCsv(*trace, o.out); !s) {
        std::fprintf(stderr, "%s: %s\n", kCmd, s.error().c_str());
        return 1;
    }
    std::fputs(headTraceReport(path, *motion, h, *trace, o.out).c_str(), stdout);
    return 0;
}

Registered registerTraceMotion(CLI::App& parent) {
    auto o = std::make_shared<MotionOptions>();
    CLI::App* cmd = parent.add_subcommand(
        "motion", "Head-pose trace (CSV) from a BVH motion-capture file, at the display rate");
    auto* bvh =
        cmd->add_option("--bvh", o->bvh, "BVH file (HIERARCHY/MOTION text)")->check(readableFile());
    auto* def = cmd->add_flag("--default", o->use_default,
                              "Use " + defaultBvhPath() + " (Debian assimp-testmodels)");
    bvh->excludes(def);
    def->excludes(bvh);
    addFinite(cmd, "--rate", o->head.rate_hz, "Display rate to resample to, Hz", 1.0, 1000.0);
    addFramesOption(cmd, o->head.frames, 0, 100'000'000, "Poses to write (0: the whole recording)");
    addOutputFileOption(cmd, o->out, "Output CSV (t_ms,qw,qx,qy,qz,x,y,z)");
    cmd->add_option("--unit", o->unit, "BVH length unit: auto, m, cm, inch or cmu (1/0.45 in)")
        ->capture_default_str();
    cmd->add_option("--joint", o->head.head_joint,
                    "Head joint name (default: Head/head, else the top joint)");
    cmd->add_option("--origin", o->origin, "Start point X,Y,Z in metres; Y is the floor height")
        ->check(parsedBy(&parseTriple, "X,Y,Z in metres", "X,Y,Z", "POINT"))
        ->capture_default_str();
    addFinite(cmd, "--yaw", o->head.yaw_deg,
              "Initial heading in degrees about +y (0 looks down -z)", -360.0, 360.0);
    addFinite(cmd, "--smooth-ms", o->head.smooth_sigma_ms,
              "Gaussian smoothing sigma in ms (0: off)", 0.0, 1000.0);
    cmd->add_flag("--keep-first-frame", o->keep_first,
                  "Keep a first frame that looks like a reference pose (CMU files start with one)");
    return {cmd, [o]() { return runTraceMotion(*o); }};
}

struct GazeOptions {
    uint64_t seed = 1;
    int frames = 1200;
    std::string out;
    GazeModelConfig model;
};

Registered registerTraceGaze(CLI::App& parent) {
    auto o = std::make_shared<GazeOptions>();
    CLI::App* cmd = parent.add_subcommand(
        "gaze", "Seeded gaze trace (CSV): fixations, main-sequence saccades, 120 Hz samples");
    addSeedOption(cmd, o->seed, "Random seed; the same seed gives the same trace");
    addFramesOption(cmd, o->frames, 1, 100'000'000, "Eye-tracker samples to write");
    addOutputFileOption(cmd, o->out, "Output CSV (t_ms,x_deg,y_deg)");
    GazeModelConfig& m = o->model;
    addFinite(cmd, "--rate", m.sample_rate_hz, "Eye-tracker sample rate, Hz", 1.0, 2000.0);
    addFinite(cmd, "--pursuit", m.pursuit_probability,
              "Probability that smooth pursuit replaces a fixation", 0.0, 1.0);
    addFinite(cmd, "--noise", m.tracker_noise_deg, "Tracker noise sigma in degrees", 0.0, 5.0);
    addFinite(cmd, "--bound-x", m.bound_x_deg, "Horizontal gaze half-range, degrees", 1.0, 80.0);
    addFinite(cmd, "--bound-y", m.bound_y_deg, "Vertical gaze half-range, degrees", 1.0, 80.0);
    Action action = [o]() -> int {
        auto trace = generateGaze(o->model, o->seed, o->frames);
        if (!trace) {
            std::fprintf(stderr, "qvr trace gaze: %s\n", trace.error().c_str());
            return 2;
        }
        if (Status s = writeGazeCsv(*trace, o->out); !s) {
            std::fprintf(stderr, "qvr trace gaze: %s\n", s.error().c_str());
            return 1;
        }
        std::fputs(gazeTraceReport(*trace, o->model, o->seed, o->out).c_str(), stdout);
        return 0;
    };
    return {cmd, action};
}

}  // namespace

QVR_REGISTER_SUBCOMMAND("trace", 10, registerTraceMotion);
QVR_REGISTER_SUBCOMMAND("trace", 20, registerTraceGaze);

static Registered registerTrace(CLI::App& app) {
    return mountSubcommands(
        app, "trace", "Make input traces: head motion from mocap, gaze (see qvr trace --help)");
}

QVR_REGISTER_COMMAND(80, registerTrace);

}  // namespace qvr::cli
