// `qvr sweep`: adaptive foveation against every fixed fovea on conditions drawn from a space,
// not taken from a list. A seed draws N conditions (link, headset share, scene, head motion,
// gaze seed); each condition runs the adaptive designs and a grid of fixed e1 once, in an order
// rotated per condition, then the adaptive designs and the best fixed e1 again; every run is
// read with the calibrated model's prediction beside it. The result is one table, the
// per-condition ratios and the spread over repetitions, and the claim's criteria judged on them.
//
// Drawing is a pure function of the seed (drawConditions); the runs go through a seam
// (ConditionRunner), so the plan, the reading and the verdicts are tested without processes.
#pragma once

#include <cstdint>
#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "qvr/core/expected.h"
#include "qvr/experiment/validation.h"

namespace qvr::experiment {

// What conditions are drawn from.
struct SweepSpace {
    // Constant links: log-uniform over this range of Mbit/s.
    double rate_min_mbps = 1.0, rate_max_mbps = 200.0;
    // Trace links (`qvr run --net` specs, "trace:FILE[@MBPS]"); a condition takes one of them
    // with probability trace_odds (none given: always a constant rate).
    std::vector<std::string> traces;
    double trace_odds = 0.4;
    // The headset's share of its core: 1 with probability full_share_odds (the default headset),
    // else uniform over [share_min, share_max] in steps of 0.05.
    double share_min = 0.3, share_max = 1.0;
    double full_share_odds = 0.25;
    std::vector<std::string> scenes;   // `qvr run --scene`
    std::vector<std::string> motions;  // `qvr run --motion`
};

// One drawn condition.
struct SweepCondition {
    int index = 0;     // 0-based, in drawing order
    std::string link;  // `qvr run --net`
    double headset_share = 1.0;
    std::string scene, motion;
    uint64_t gaze_seed = 1;  // `qvr run --seed`
};

// N conditions from `seed`: the same seed and space give the same conditions on every machine
// (a 64-bit Mersenne Twister mapped to [0, 1) by hand, no std distribution).
std::vector<SweepCondition> drawConditions(const SweepSpace& space, uint64_t seed, int count);

// A link's mean capacity in Mbit/s: a constant's rate, a trace's recorded (or rescaled) mean;
// none for a link without a rate (none) or one that does not load.
std::optional<double> linkMeanMbps(const std::string& link);

// What `qvr sweep` was asked, checked.
struct SweepOptions {
    uint64_t seed = 1;
    int conditions = 16;
    SweepSpace space;
    std::vector<std::string> adaptive = {"qvr", "sw", "ffr", "aimd"};  // run in every take
    std::vector<double> fixed_grid_deg = {2, 4, 6, 8, 10, 12, 15, 20};
    int repeats = 3;  // takes after the grid's
    int frames = 150;
    std::string executable;  // the qvr the runs start
    std::string hardware;    // a calibration for every run (empty: each run's own choice)
    // Without --hardware, a scene's first run measures its calibration afresh (qvr run
    // --recalibrate) and the scene's later runs use it: a cached one from another hour of a
    // drifting host biased every prediction of a scene alike. True: the cache as it is.
    bool cached_calibration = false;
    std::string profile = "default";
    std::string out = "qvr-sweep";
    bool dry_run = false;
    std::string from;  // an earlier sweep's folder: its runs judged, none run (empty: run them)
    std::vector<std::string> skipped_designs;  // named, but refused by the runtime: why
};

// The options as the command line gives them, before they are checked.
struct SweepArgs {
    uint64_t seed = 1;
    int conditions = 16;
    std::string traces;  // comma-separated files, folders (their *.down) or trace: specs
    std::string scenes, motions, designs, fixed_grid;
    double share_min = 0.3, share_max = 1.0;
    double rate_min_mbps = 1.0, rate_max_mbps = 200.0;
    int repeats = 3;
    int frames = 150;
    std::string hardware, profile = "default", out = "qvr-sweep", from;
    bool dry_run = false;
    bool cached_calibration = false;
};
// The defaults of a list the arguments leave empty: the shared Mahimahi traces (each also at a
// 2 Mbit/s mean) and the repository's data/network/*.down; builtin:room, two OpenArena levels
// and a glTF model; three CMU motions.
SweepArgs defaultSweepArgs();
// Checks every option (bad input: the message for "qvr sweep: ..."); designs the runtime
// refuses are left out and named in skipped_designs.
Expected<SweepOptions> sweepOptions(const SweepArgs& args);

// One design's reading in one run.
struct DesignReading {
    std::string design;
    double fps = 0.0, mtp_ms_p99 = 0.0, bytes_per_frame = 0.0, e1_deg = 0.0;
    // The counted frames, and those that re-warped older layers because their own came late.
    int frames = 0, frames_reused = 0;
    std::optional<double> predicted_fps;  // the calibrated model's
    // The model with the design's costs at the speed the run's probes measured (docs/MODEL.md
    // §11): how much of the error is the host running faster or slower than when calibrated.
    // None under --headset-share (no probes there).
    std::optional<double> predicted_fps_at_probe_speed;
    std::optional<double> fpsErrorPct() const;  // signed, percent of the measurement
    std::optional<double> fpsErrorAtProbeSpeedPct() const;
    // Frames per second shown with their own layers: fps × (frames − frames_reused) / frames.
    // What the sweep judges designs on: `fps` also counts frames that re-warped an older
    // periphery, so a design whose layers stop arriving keeps its frame rate (docs/MODEL.md §12).
    double freshFps() const;
};

// The designs of one `qvr run` summary.json, in the order given (missing ones left out).
std::vector<DesignReading> readingsFromSummary(const nlohmann::json& summary,
                                               const std::vector<std::string>& designs);
// Every design of one `qvr run` summary.json.
std::vector<DesignReading> readingsFromSummary(const nlohmann::json& summary);

// What one run of a condition gave.
struct ConditionRun {
    bool ok = false;
    std::string note;  // why not
    std::vector<DesignReading> designs;
};

// The seam: runs these designs, in this order, under this condition.
class ConditionRunner {
public:
    virtual ~ConditionRunner() = default;
    // `tag` names the run among the sweep's ("c03_grid", "c03_r2").
    virtual ConditionRun run(const SweepCondition& condition,
                             const std::vector<std::string>& designs, const std::string& tag) = 0;
    // The signal that stopped the sweep (0: none): no run starts after it.
    virtual int stopSignal() const { return 0; }
};

// The runs an earlier sweep wrote (`qvr sweep --from DIR`): each take read from
// DIR/<tag>/summary.json, every design it holds, nothing run. The same seed, conditions and
// repeats give the same tags.
class StoredConditionRunner final : public ConditionRunner {
public:
    explicit StoredConditionRunner(std::string dir) : m_dir(std::move(dir)) {}
    ConditionRun run(const SweepCondition& condition, const std::vector<std::string>& designs,
                     const std::string& tag) override;

private:
    std::string m_dir;
};

// `qvr run` in a child process per run (through a ChildRunner), read from its summary.json.
class ProcessConditionRunner final : public ConditionRunner {
public:
    ProcessConditionRunner(const SweepOptions& options, ChildRunner& children)
        : m_options(options), m_children(children) {}
    ConditionRun run(const SweepCondition& condition, const std::vector<std::string>& designs,
                     const std::string& tag) override;
    int stopSignal() const override { return m_children.stopSignal(); }
    // The run's command line and where it writes; `recalibrate`: the scene's first run.
    ChildCommand command(const SweepCondition& condition, const std::vector<std::string>& designs,
                         const std::string& tag, bool recalibrate = false) const;

private:
    const SweepOptions& m_options;
    ChildRunner& m_children;
    std::set<std::string> m_calibrated;  // scenes whose calibration this sweep measured
};

// The designs of a condition's take, in the order it runs them: take 0 the adaptive designs and
// the grid, later takes the adaptive designs and `best_fixed`; rotated left by condition +
// take, so no design always runs first.
std::vector<std::string> takeDesigns(const SweepOptions& options, int condition, int take,
                                     const std::string& best_fixed);

// One design's run under one condition.
struct SweepRow {
    int condition = 0;
    int take = 0;  // 0: the grid's run; 1…: the repetitions
    DesignReading reading;
};

// A condition's verdicts. Every FPS is DesignReading::freshFps. The best fixed e1 is chosen on
// the grid's take and judged on the others: a ratio is of the medians over the takes that ran
// both designs, the grid's take left out when a repeat ran both (choosing the highest of nine
// noisy values and judging on that same value favours it; docs/MODEL.md §13).
struct ConditionVerdict {
    int condition = 0;
    std::optional<double> link_mbps;
    std::string best_fixed;  // the fixed design with the highest FPS in the grid's take
    double best_fixed_fps = 0.0;
    std::optional<double> qvr_over_best, qvr_over_ffr, qvr_over_aimd, mtp_p99_over_best;
    // qvr over the best fixed e1 by `fps`, reused frames counted: beside the verdict, not in it.
    std::optional<double> qvr_over_best_all_frames;
    // (max − min) / median of FPS over the takes, percent, by design (qvr, best fixed, …).
    std::vector<std::pair<std::string, double>> spread_pct;
};

struct SweepResult {
    std::vector<SweepCondition> conditions;
    std::vector<SweepRow> rows;  // in the order they ran
    std::vector<ConditionVerdict> verdicts;
    int failed_runs = 0;
    int stop_signal = 0;
    double seconds = 0.0;
};

// Runs every condition's takes through `runner`, progress on `out`.
SweepResult executeSweep(const SweepOptions& options, ConditionRunner& runner,
                         std::FILE* out = stdout);
// The verdicts from the rows (executeSweep calls it).
std::vector<ConditionVerdict> conditionVerdicts(const SweepOptions& options,
                                                const SweepResult& result);

// One of the claim's criteria judged on the sweep.
struct SweepCriterion {
    std::string name;
    bool pass = false;
    std::string detail;
};
std::vector<SweepCriterion> sweepCriteria(const SweepResult& result);

// The outputs: the table of every run, the conditions with their ratios, the criteria.
std::string sweepMarkdown(const SweepOptions& options, const SweepResult& result);
std::string sweepCsv(const SweepResult& result);
nlohmann::json sweepJson(const SweepOptions& options, const SweepResult& result);

// What `qvr sweep` does: draws, runs (or prints the plan), writes sweep.md, sweep.csv and
// sweep.json into options.out. The exit status: 0, 1 with failed runs, 130 when stopped.
int runSweep(const SweepOptions& options, ConditionRunner& runner, std::FILE* out = stdout,
             std::FILE* err = stderr);

}  // namespace qvr::experiment
