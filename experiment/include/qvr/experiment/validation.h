// `qvr validate`: the calibrated simulator's correlation sheet. Each scene is calibrated (`qvr
// calibrate`, apart from every run), then `qvr run` runs every design under each condition —
// links × scenes × pipeline depths, a few repetitions — and predicts it with its repetition's
// calibration; the sheet tabulates the signed prediction errors with their mean absolute and
// worst values (docs/MODEL.md §12).
//
// A plan in (planValidation), its steps taken through a ChildRunner (executeValidation), a
// result out (ValidationResult), the sheet from the result (validationMarkdown,
// validationJson). runValidation does all of it for `qvr validate`.
#pragma once

#include <cstddef>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace qvr::experiment {

// When each scene is calibrated.
enum class CalibrationPolicy {
    // Anew for each repetition, just before that repetition's runs of the scene: the
    // repetitions repeat the whole measurement (calibrate, predict, run), so a host whose speed
    // moves from one minute to the next puts each calibration's error in its own repetition,
    // and the spread over repetitions states it.
    kPerRep,
    kOnce,   // once per scene, before any run
    kGiven,  // not at all: every run uses the calibration file given (one scene)
};
// "per-rep", "once", "hardware": the policy as validation.json names it.
const char* calibrationPolicyName(CalibrationPolicy policy);

// What `qvr validate` was asked, checked: every list non-empty, each depth 1 or 2.
struct ValidationOptions {
    std::string executable;                           // the qvr the children run
    std::string designs = "local,remote,ffr,sw,qvr";  // every run's --designs, as given
    std::vector<std::string> links;                   // `qvr run --net` specs
    std::vector<std::string> scenes;
    std::vector<int> depths;  // frames in flight
    // Head motions (`qvr run --motion`) and headset shares (`--headset-share`) of every run.
    std::vector<std::string> motions = {"default"};
    std::vector<double> headset_shares = {1.0};
    // When set, the one scene calibrated: every scene's runs are predicted with its calibration
    // (out of sample for the others). Empty: each scene is calibrated on itself.
    std::string calibration_scene;
    int frames = 40;  // per design per run
    int reps = 1;
    // A calibration or run taken again, up to this many times, when its speed probes say the
    // machine was not steady over it; the steadiest take counts.
    int retakes = 1;
    CalibrationPolicy calibrate = CalibrationPolicy::kPerRep;  // kPerRep or kOnce
    std::string hardware;  // a calibration to use instead of calibrating (absolute; kGiven)
    std::string profile = "default";
    std::string out = "qvr-validate";  // the sheet's folder
    bool dry_run = false;              // print the plan's commands, run nothing
};

// One calibration of a scene: for one repetition (kPerRep) or for every one.
struct PlannedCalibration {
    std::string scene;
    int rep = 0;  // 0-based repetition it serves (0 when it serves every one)
};

// One condition in one repetition: a `qvr run` of every design.
struct PlannedRun {
    std::string scene, link;
    int depth = 1;
    std::string motion = "default";
    double headset_share = 1.0;
    int rep = 0;             // 0-based
    size_t calibration = 0;  // the index in ValidationPlan::calibrations that predicts it
};

struct PlannedStep {
    enum class Kind { kCalibration, kRun };
    Kind kind = Kind::kRun;
    size_t index = 0;  // into ValidationPlan::calibrations or ::runs
};

struct ValidationPlan {
    ValidationOptions options;
    CalibrationPolicy policy = CalibrationPolicy::kPerRep;  // kGiven when options.hardware is set
    std::vector<PlannedCalibration> calibrations;
    std::vector<PlannedRun> runs;
    std::vector<PlannedStep> steps;  // in the order they are taken
    size_t conditions() const;       // links × scenes × depths × motions × shares
};

// The sheet's steps, in order: with kPerRep each repetition calibrates each scene just before
// that scene's runs; with kOnce and kGiven every scene's calibration comes before any run.
ValidationPlan planValidation(const ValidationOptions& options);

// A child process of the sheet.
struct ChildCommand {
    std::string line;         // for /bin/sh; its output goes to the log
    std::string output;       // the calibration file or the run's folder
    std::string log_path;     // output + ".log"
    std::string result_path;  // read when it exits 0: FILE.json or DIR/summary.json
};
// A `qvr run` child writing into the folder `output`: its log beside the folder, its result the
// folder's summary.json. The caller writes its line.
ChildCommand runChildIn(std::string output);
// Take `take` (0-based) of a planned calibration: `qvr calibrate --out
// OUT/calibration-SCENE[-rREP][-tTAKE].toml`.
ChildCommand calibrationTake(const ValidationPlan& plan, size_t calibration, int take);
// Take `take` of a planned run, predicted with `calibration_file`: `qvr run --out
// OUT/SCENE_LINK_dDEPTH_rREP[_tTAKE]`.
ChildCommand runTake(const ValidationPlan& plan, size_t run, int take,
                     const std::string& calibration_file);

// What a child left behind.
struct ChildOutcome {
    int exit_code = -1;     // 128 + N for signal N; -1 when it could not start
    nlohmann::json result;  // its result file, parsed when it exited 0 (else null)
};

// The seam between the sheet and the processes it starts.
class ChildRunner {
public:
    virtual ~ChildRunner() = default;
    virtual ChildOutcome run(const ChildCommand& command) = 0;
    // The signal that asked the sheet to stop (0: none): the child under way was cut short
    // and no further one starts.
    virtual int stopSignal() const = 0;
};

// Starts each command through /bin/sh, stdin from /dev/null. While it exists, SIGINT and
// SIGTERM stop the sheet: the signal is passed to the child under way (a run then ends its
// design and writes what it measured), and stopSignal() reports it. One at a time.
class ProcessRunner final : public ChildRunner {
public:
    ProcessRunner();
    ~ProcessRunner() override;
    ProcessRunner(const ProcessRunner&) = delete;
    ProcessRunner& operator=(const ProcessRunner&) = delete;
    ChildOutcome run(const ChildCommand& command) override;
    int stopSignal() const override;
};

// One design × condition cell of the sheet: a reading per counted run.
struct ValidationRow {
    std::string scene, link, design;
    int depth = 0;
    std::string motion = "default";
    double headset_share = 1.0;
    std::vector<double> fps_measured, fps_predicted;
    std::vector<double> fps_error_pct, mtp_error_pct, bytes_error_pct, e1_error_deg;
    // Each side's own cost against the model's ("Stage errors"): a host that changed speed
    // since the calibration shows here as well as in the FPS.
    std::vector<double> headset_cost_error_pct, server_cost_error_pct;
    // The FPS error with each design's costs at its speed probes' speed (qvr run's
    // predicted_at_probe_speed).
    std::vector<double> fps_error_pct_at_probe_speed;
};

// Cells in the order they were first read.
class ValidationRows {
public:
    // Every design of a run's summary.json that has a prediction.
    void add(const nlohmann::json& summary, const std::string& scene, const std::string& link,
             int depth, const std::string& motion = "default", double headset_share = 1.0);
    const std::vector<ValidationRow>& rows() const { return m_rows; }
    // The cell of `row`'s scene, link, depth, motion, share and design (nullptr: none).
    const ValidationRow* find(const ValidationRow& row) const;

private:
    std::vector<ValidationRow> m_rows;
    std::map<std::string, size_t> m_index;  // scene|link|depth|motion|share|design
};

struct CalibrationRecord {
    std::string scene;
    int rep = 0;  // 1-based; 0 when the calibration serves every repetition
    std::string file;
    double probe_spread_pct = 0.0;  // the chosen take's (calibrationSpreadPct)
};

struct ValidationResult {
    std::string machine;
    double seconds = 0.0;
    ValidationRows rows;              // the counted take of every run
    ValidationRows rows_first_takes;  // the first take of every counted run
    ValidationRows rows_steady;       // the counted runs whose probes stayed within 10%
    std::vector<CalibrationRecord> calibrations;
    int failed_runs = 0;  // and failed per-repetition calibrations
    int runs_retaken = 0;
    int runs_unsteady_after_retakes = 0;
    size_t runs_counted = 0, runs_steady = 0;
    std::vector<double> run_speed_spread_pct;  // per counted run with probes: the largest spread
    std::vector<double> run_disturbance_pct;   // per counted run with probes: runDisturbancePct
    int stop_signal = 0;                       // the signal that stopped the sheet (0: none)
    int aborted_exit = 0;  // a calibration ended the sheet with no report: its exit status
};
// 0, or 1 with failed runs, 130 when stopped, or the abort's status.
int validationExitCode(const ValidationResult& result);

// How far the machine moved from steady over a run, in percent, by the run's own speed probes
// (summary.json calibration.speed_reference): the larger of the probes' spread over the run and
// their mean's distance from the calibration's reference, either side. NaN when the run took
// no probes (a calibration without a reference).
double runDisturbancePct(const nlohmann::json& summary);
// The larger of the two sides' spread of a run's speed probes, in percent (NaN without both).
double runSpeedSpreadPct(const nlohmann::json& summary);
// The largest spread of a calibration's speed probes (its JSON copy's speed_reference.probes),
// either side, in percent; NaN without probes.
double calibrationSpreadPct(const nlohmann::json& calibration);
// Steady by the speed probes: within kUnsteadySpeedPct, or no probe taken (NaN: nothing to
// tell, so a take without probes is never taken again).
bool steadyByProbes(double pct);
// Whether a take `pct` from steady beats the steadiest so far: NaN (no probes) counts as steady.
bool steadierTake(double pct, double best_pct);
// What follows a take's "done": how far its probes moved, and whether it is taken again.
std::string takeNote(double pct, bool more_takes);

// The absolute values of cells' mean errors: their mean and the worst (NaN without cells).
struct AbsError {
    double mean = std::numeric_limits<double>::quiet_NaN();
    double worst = std::numeric_limits<double>::quiet_NaN();
    size_t cells = 0;
};
// Over the cells of `order`, each read in `table` (skipped when absent there or not finite).
AbsError absError(const ValidationRows& order, const ValidationRows& table,
                  std::vector<double> ValidationRow::*field);

struct ValidationStats {
    AbsError fps, mtp, bytes, e1, fps_at_probe_speed;
    AbsError fps_every_run;    // over single runs, not cells' means (cells: runs)
    AbsError fps_first_takes;  // what the retakes changed
    // Where the machine held its calibration's speed.
    AbsError fps_steady, mtp_steady;
    double run_speed_spread_median_pct = std::numeric_limits<double>::quiet_NaN();  // none: NaN
    size_t runs_unsteady = 0;  // runs whose probes spread over 10%
};
ValidationStats summariseValidation(const ValidationResult& result);

// The sheet: one table row per cell, then the aggregate lines.
std::string validationMarkdown(const ValidationPlan& plan, const ValidationResult& result);
// validation.json.
nlohmann::json validationJson(const ValidationPlan& plan, const ValidationResult& result);

// Takes the plan's steps through `runner`, progress on `out`, failures on `err`. Nothing
// starts after a stop.
ValidationResult executeValidation(const ValidationPlan& plan, ChildRunner& runner,
                                   std::FILE* out = stdout, std::FILE* err = stderr);
// What `qvr validate` does: creates the folder, plans, prints the plan (dry run) or executes it
// and writes validation.md and validation.json. The process exit status.
int runValidation(const ValidationOptions& options, ChildRunner& runner, std::FILE* out = stdout,
                  std::FILE* err = stderr);

// A Mahimahi trace of the shared data: searched upward from the working directory and the
// executable's folder for shared/data/network/FILE or data/network/FILE (empty: none).
std::string findMahimahiTrace(const std::string& file);
// The folders findMahimahiTrace searches that exist, nearest first.
std::vector<std::string> mahimahiTraceFolders();

}  // namespace qvr::experiment
