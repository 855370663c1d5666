// `qvr trace motion|gaze`: head-motion traces from BVH motion capture and seeded gaze traces
// (paper §5 workloads; §7 120 Hz eye trackers), written as the CSV formats of docs/MOTION.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.h"
#include "options.h"
#include "qvr/trace/gaze_model.h"
#include "qvr/trace/head_motion.h"

namespace qvr::cli {

// Sub-commands of `qvr trace`. Each registers a RegisterFn that adds its sub-command to the
// `trace` app; registerTrace mounts them all. A later file (e.g. cmd_trace_record.cpp) adds one
// by declaring `bool addTraceCommand(int order, RegisterFn fn);` in namespace qvr::cli and
// registering at static-initialisation time, as QVR_REGISTER_COMMAND does for top-level ones.
struct TraceEntry {
    int order;
    RegisterFn fn;
};

static std::vector<TraceEntry>& traceRegistry() {
    static std::vector<TraceEntry> registry;
    return registry;
}

bool addTraceCommand(int order, RegisterFn fn) {
    traceRegistry().push_back({order, fn});
    return true;
}

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
    double rate_hz = 90.0;
    int frames = 0;
    std::string out;
    std::string unit = "auto";
    std::string joint;
    std::string origin = "0,0,0";
    double yaw_deg = 0.0;
    double smooth_ms = 0.0;
    bool keep_first = false;
};

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
    cmd->add_option("--rate", o->rate_hz, "Display rate to resample to, Hz")
        ->check(finiteRange(1.0, 1000.0))
        ->capture_default_str();
    addFramesOption(cmd, o->frames, 0, 100'000'000, "Poses to write (0: the whole recording)");
    cmd->add_option("--out", o->out, "Output CSV (t_ms,qw,qx,qy,qz,x,y,z)")
        ->required()
        ->check(writableFile());
    cmd->add_option("--unit", o->unit, "BVH length unit: auto, m, cm, inch or cmu (1/0.45 in)")
        ->capture_default_str();
    cmd->add_option("--joint", o->joint,
                    "Head joint name (default: Head/head, else the top joint)");
    cmd->add_option("--origin", o->origin, "Start point X,Y,Z in metres; Y is the floor height")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                glm::vec3 v;
                return parseTriple(text, v) ? std::string()
                                            : "must be X,Y,Z in metres, got '" + text + "'";
            },
            "X,Y,Z", "POINT"))
        ->capture_default_str();
    cmd->add_option("--yaw", o->yaw_deg, "Initial heading in degrees about +y (0 looks down -z)")
        ->check(finiteRange(-360.0, 360.0))
        ->capture_default_str();
    cmd->add_option("--smooth-ms", o->smooth_ms, "Gaussian smoothing sigma in ms (0: off)")
        ->check(finiteRange(0.0, 1000.0))
        ->capture_default_str();
    cmd->add_flag("--keep-first-frame", o->keep_first,
                  "Keep a first frame that looks like a reference pose (CMU files start with one)");
    Action action = [o]() -> int {
        if (o->bvh.empty() && !o->use_default) {
            std::fprintf(stderr, "qvr trace motion: give --bvh FILE or --default\n");
            return 2;
        }
        const std::string path = o->use_default ? defaultBvhPath() : o->bvh;
        HeadMotionOptions h;
        auto unit = bvhUnitFromName(o->unit);
        if (!unit) {
            std::fprintf(stderr, "qvr trace motion: --unit: %s\n", unit.error().c_str());
            return 2;
        }
        h.unit = *unit;
        h.head_joint = o->joint;
        parseTriple(o->origin, h.origin_m);  // checked when parsed
        h.yaw_deg = o->yaw_deg;
        h.rate_hz = o->rate_hz;
        h.frames = o->frames;
        h.smooth_sigma_ms = o->smooth_ms;
        h.drop_reference_frame = !o->keep_first;
        auto motion = loadBvhFile(path);
        if (!motion) {
            std::fprintf(stderr, "qvr trace motion: %s%s\n", motion.error().c_str(),
                         o->use_default ? " (install the Debian package assimp-testmodels)" : "");
            return 2;
        }
        auto trace = headTraceFromBvh(*motion, h);
        if (!trace) {
            std::fprintf(stderr, "qvr trace motion: %s: %s\n", path.c_str(), trace.error().c_str());
            return 2;
        }
        if (Status s = writePoseCsv(*trace, o->out); !s) {
            std::fprintf(stderr, "qvr trace motion: %s\n", s.error().c_str());
            return 1;
        }
        const auto& s = trace->samples;
        double sum_deg_s = 0.0;
        double max_deg_s = 0.0;
        for (size_t i = 1; i < s.size(); ++i) {
            const double v =
                angleBetweenDeg(s[i - 1].pose.orientation, s[i].pose.orientation) * o->rate_hz;
            sum_deg_s += v;
            max_deg_s = std::max(max_deg_s, v);
        }
        const BvhUnit used = h.unit == BvhUnit::kAuto ? detectBvhUnit(*motion) : h.unit;
        auto head = findHeadJoint(*motion, h.head_joint);
        fmt::print("{}: {} frames at {:.4g} Hz, {} joints, unit {} ({:.5f} m), head joint '{}'\n",
                   path, motion->frame_count, 1.0 / motion->frame_time_s, motion->joints.size(),
                   bvhUnitName(used), bvhUnitMetres(used),
                   motion->joints[static_cast<size_t>(*head)].name);
        fmt::print(
            "wrote {}: {} poses at {} Hz ({:.2f} s), head turn mean {:.1f} deg/s, max "
            "{:.1f} deg/s\n",
            o->out, s.size(), o->rate_hz, s.empty() ? 0.0 : s.back().t_ms / 1000.0,
            s.size() > 1 ? sum_deg_s / static_cast<double>(s.size() - 1) : 0.0, max_deg_s);
        return 0;
    };
    return {cmd, action};
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
    cmd->add_option("--out", o->out, "Output CSV (t_ms,x_deg,y_deg)")
        ->required()
        ->check(writableFile());
    cmd->add_option("--rate", o->model.sample_rate_hz, "Eye-tracker sample rate, Hz")
        ->check(finiteRange(1.0, 2000.0))
        ->capture_default_str();
    cmd->add_option("--pursuit", o->model.pursuit_probability,
                    "Probability that smooth pursuit replaces a fixation")
        ->check(finiteRange(0.0, 1.0))
        ->capture_default_str();
    cmd->add_option("--noise", o->model.tracker_noise_deg, "Tracker noise sigma in degrees")
        ->check(finiteRange(0.0, 5.0))
        ->capture_default_str();
    cmd->add_option("--bound-x", o->model.bound_x_deg, "Horizontal gaze half-range, degrees")
        ->check(finiteRange(1.0, 80.0))
        ->capture_default_str();
    cmd->add_option("--bound-y", o->model.bound_y_deg, "Vertical gaze half-range, degrees")
        ->check(finiteRange(1.0, 80.0))
        ->capture_default_str();
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
        int counts[3] = {0, 0, 0};
        double amplitude_sum = 0.0;
        for (const auto& e : trace->events) {
            ++counts[static_cast<int>(e.kind)];
            if (e.kind == GazeEventKind::kSaccade)
                amplitude_sum += e.amplitude_deg;
        }
        const int saccades = counts[static_cast<int>(GazeEventKind::kSaccade)];
        fmt::print(
            "wrote {}: {} samples at {} Hz ({:.2f} s), seed {}: {} fixations, {} pursuits, "
            "{} saccades (mean amplitude {:.1f} deg)\n",
            o->out, trace->samples.size(), o->model.sample_rate_hz,
            trace->samples.back().t_ms / 1000.0, o->seed,
            counts[static_cast<int>(GazeEventKind::kFixation)],
            counts[static_cast<int>(GazeEventKind::kPursuit)], saccades,
            saccades > 0 ? amplitude_sum / saccades : 0.0);
        return 0;
    };
    return {cmd, action};
}

[[maybe_unused]] const bool kMotionRegistered = addTraceCommand(10, &registerTraceMotion);
[[maybe_unused]] const bool kGazeRegistered = addTraceCommand(20, &registerTraceGaze);

}  // namespace

static Registered registerTrace(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand(
        "trace", "Make input traces: head motion from mocap, gaze (see qvr trace --help)");
    cmd->require_subcommand(1);
    auto entries = traceRegistry();
    std::sort(entries.begin(), entries.end(),
              [](const auto& a, const auto& b) { return a.order < b.order; });
    auto subs = std::make_shared<std::vector<Registered>>();
    for (const auto& e : entries)
        subs->push_back(e.fn(*cmd));
    Action action = [subs]() -> int {
        for (auto& s : *subs) {
            if (s.command->parsed())
                return s.action();
        }
        return 2;
    };
    return {cmd, action};
}

QVR_REGISTER_COMMAND(80, registerTrace);

}  // namespace qvr::cli
