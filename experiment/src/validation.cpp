// The correlation sheet taken: every calibration and run of the plan through a ChildRunner,
// each taken again while its speed probes say the machine was unsteady (validation.h).
#include "qvr/experiment/validation.h"

#include <chrono>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "qvr/core/text_file.h"
#include "qvr/experiment/calibration.h"
#include "qvr/experiment/host.h"

namespace qvr::experiment {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

enum class CalibrationStatus { kDone, kStopped, kFailed, kBadInput };

// Takes a plan's steps in order. A calibration or run whose speed probes moved over 10% (a
// run: across it, or its mean from the calibration's reference) was not measured on a steady
// machine: it is taken again, up to --retakes times, and the steadiest take counts — chosen by
// the probes alone, never by the prediction's error.
class SheetTaker {
public:
    SheetTaker(const ValidationPlan& plan, ChildRunner& runner, std::FILE* out, std::FILE* err)
        : m_plan(plan),
          m_runner(runner),
          m_out(out),
          m_err(err),
          m_calibration_file(plan.calibrations.size()) {}

    ValidationResult take() {
        for (const PlannedStep& step : m_plan.steps) {
            if (m_result.stop_signal != 0 || m_result.aborted_exit != 0)
                break;
            if (step.kind == PlannedStep::Kind::kCalibration)
                calibrationStep(step.index);
            else if (!m_calibration_file[m_plan.runs[step.index].calibration].empty())
                run(step.index);
        }
        return std::move(m_result);
    }

    // The dry run: every step's first take, printed.
    void print() {
        for (const PlannedStep& step : m_plan.steps) {
            if (step.kind == PlannedStep::Kind::kCalibration) {
                if (useGiven(step.index))
                    continue;
                const ChildCommand cmd = calibrationTake(m_plan, step.index, 0);
                printCalibrationProgress(step.index, 0);
                fmt::print(m_out, "\n    {}\n", cmd.line);
                m_calibration_file[step.index] = cmd.output;
                continue;
            }
            const PlannedRun& r = m_plan.runs[step.index];
            printRunProgress(r, 0);
            fmt::print(m_out, "\n    {}\n",
                       runTake(m_plan, step.index, 0, m_calibration_file[r.calibration]).line);
        }
    }

private:
    bool perRep() const { return m_plan.policy == CalibrationPolicy::kPerRep; }

    // kGiven: the file given stands for the calibration.
    bool useGiven(size_t i) {
        if (m_plan.policy != CalibrationPolicy::kGiven)
            return false;
        fmt::print(m_out, "  using the calibration {} (--hardware) on {}\n",
                   m_plan.options.hardware, m_plan.calibrations[i].scene);
        m_calibration_file[i] = m_plan.options.hardware;
        return true;
    }

    void printCalibrationProgress(size_t i, int take) {
        const PlannedCalibration& c = m_plan.calibrations[i];
        fmt::print(m_out, "  calibrating on {}{}{} ...", c.scene,
                   perRep() ? fmt::format(" for rep {}", c.rep + 1) : "",
                   take == 0 ? "" : fmt::format(" (take {})", take + 1));
        std::fflush(m_out);
    }

    void printRunProgress(const PlannedRun& r, int take) {
        fmt::print(m_out, "  {} | {} | depth {}{}{} | rep {}{} ...", r.scene, r.link, r.depth,
                   r.motion == "default" ? "" : " | motion " + r.motion,
                   r.headset_share < 1.0 ? fmt::format(" | share {:g}", r.headset_share) : "",
                   r.rep + 1, take == 0 ? "" : fmt::format(" take {}", take + 1));
        std::fflush(m_out);
    }

    // A repetition's calibration stopped by a signal ends the sheet as a run's stop does (the
    // runs that ended are reported); one that failed leaves that repetition's runs of the scene
    // without a prediction: a failure, and the sheet goes on. Bad input (exit 2 from calibrate:
    // a scene or profile it refuses) ends the sheet with 2, and so does any failure of a
    // calibration that serves every repetition, with no report.
    void calibrationStep(size_t i) {
        if (useGiven(i))
            return;
        const CalibrationStatus status = calibrate(i);
        if (status == CalibrationStatus::kDone)
            return;
        if (!perRep())
            m_result.aborted_exit = status == CalibrationStatus::kStopped    ? 130
                                    : status == CalibrationStatus::kBadInput ? 2
                                                                             : 1;
        else if (status == CalibrationStatus::kStopped)
            m_result.stop_signal = m_runner.stopSignal();
        else if (status == CalibrationStatus::kBadInput)
            m_result.aborted_exit = 2;
        else
            ++m_result.failed_runs;
    }

    CalibrationStatus calibrate(size_t i) {
        const PlannedCalibration& c = m_plan.calibrations[i];
        double best_spread = INFINITY;
        int best_take = 0;
        std::string best_file;
        for (int take = 0; take <= m_plan.options.retakes; ++take) {
            const ChildCommand cmd = calibrationTake(m_plan, i, take);
            printCalibrationProgress(i, take);
            const ChildOutcome outcome = m_runner.run(cmd);
            if (const int sig = m_runner.stopSignal(); sig != 0) {
                fmt::print(m_err, "\nqvr validate: stopped (signal {}) while calibrating\n", sig);
                return CalibrationStatus::kStopped;
            }
            if (outcome.exit_code != 0) {
                fmt::print(m_err,
                           "\nqvr validate: calibration on {} failed (exit {}), see {}.log\n",
                           c.scene, outcome.exit_code, cmd.output);
                return outcome.exit_code == 2 ? CalibrationStatus::kBadInput
                                              : CalibrationStatus::kFailed;
            }
            const double sp = calibrationSpreadPct(outcome.result);
            if (steadierTake(sp, best_spread)) {
                best_file = cmd.output;
                best_spread = sp;
                best_take = take;
            }
            fmt::print(m_out, " done{}\n", takeNote(sp, take < m_plan.options.retakes));
            if (steadyByProbes(sp))
                break;
        }
        if (best_take > 0)
            fmt::print(m_out, "  on {} the runs use {}, the steadiest\n", c.scene, best_file);
        m_calibration_file[i] = best_file;
        m_result.calibrations.push_back(
            {c.scene, perRep() ? c.rep + 1 : 0, best_file, best_spread});
        return CalibrationStatus::kDone;
    }

    // A run's takes, the steadiest counted.
    void run(size_t i) {
        const PlannedRun& r = m_plan.runs[i];
        json first, best;
        double best_disturbance = INFINITY;
        for (int take = 0; take <= m_plan.options.retakes; ++take) {
            const ChildCommand cmd = runTake(m_plan, i, take, m_calibration_file[r.calibration]);
            printRunProgress(r, take);
            ChildOutcome outcome = m_runner.run(cmd);
            if (const int sig = m_runner.stopSignal(); sig != 0) {  // cut short: not counted
                fmt::print(m_out, " stopped\n");
                m_result.stop_signal = sig;
                break;
            }
            const json& j = outcome.result;
            if (outcome.exit_code != 0 || !j.is_object() || !j.contains("designs")) {
                ++m_result.failed_runs;
                fmt::print(m_out, " failed (exit {}), see {}.log\n", outcome.exit_code, cmd.output);
                break;
            }
            const double dist = runDisturbancePct(j);
            if (take == 0)
                first = j;
            else
                ++m_result.runs_retaken;
            if (steadierTake(dist, best_disturbance)) {
                best = j;
                best_disturbance = dist;
            }
            fmt::print(m_out, " done{}\n", takeNote(dist, take < m_plan.options.retakes));
            if (steadyByProbes(dist))
                break;
        }
        if (!best.is_null())
            count(r, first, best, best_disturbance);
    }

    void count(const PlannedRun& r, const json& first, const json& best, double disturbance) {
        if (!steadyByProbes(disturbance))
            ++m_result.runs_unsteady_after_retakes;
        if (std::isfinite(disturbance)) {  // the spread is 0, not a reading, without probes
            if (const double sp = runSpeedSpreadPct(best); std::isfinite(sp))
                m_result.run_speed_spread_pct.push_back(sp);
            m_result.run_disturbance_pct.push_back(disturbance);
        }
        m_result.rows.add(best, r.scene, r.link, r.depth, r.motion, r.headset_share);
        ++m_result.runs_counted;
        m_result.rows_first_takes.add(first, r.scene, r.link, r.depth, r.motion, r.headset_share);
        // NaN (no probes): not judged, so not in the steady runs' sheet either.
        if (disturbance <= kUnsteadySpeedPct) {
            m_result.rows_steady.add(best, r.scene, r.link, r.depth, r.motion, r.headset_share);
            ++m_result.runs_steady;
        }
    }

    const ValidationPlan& m_plan;
    ChildRunner& m_runner;
    std::FILE* m_out;
    std::FILE* m_err;
    std::vector<std::string> m_calibration_file;  // per planned calibration (empty: none)
    ValidationResult m_result;
};

}  // namespace

ValidationResult executeValidation(const ValidationPlan& plan, ChildRunner& runner, std::FILE* out,
                                   std::FILE* err) {
    return SheetTaker(plan, runner, out, err).take();
}

int runValidation(const ValidationOptions& options, ChildRunner& runner, std::FILE* out,
                  std::FILE* err) {
    std::error_code ec;
    fs::create_directories(options.out, ec);
    if (ec) {
        fmt::print(err, "qvr validate: cannot create '{}': {}\n", options.out, ec.message());
        return 1;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const ValidationPlan plan = planValidation(options);
    const std::string machine = machineDescription();
    fmt::print(out,
               "qvr validate: {} conditions ({} links × {} scenes × {} depths) × {} "
               "repetition(s), designs {}, {} frames each; {}\n",
               plan.conditions(), options.links.size(), options.scenes.size(),
               options.depths.size(), options.reps, options.designs, options.frames, machine);
    if (options.dry_run) {
        SheetTaker(plan, runner, out, err).print();
        return 0;
    }
    ValidationResult result = executeValidation(plan, runner, out, err);
    if (result.aborted_exit != 0)
        return result.aborted_exit;
    result.machine = machine;
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string md = validationMarkdown(plan, result);
    fmt::print(out, "\n{}", md);
    const fs::path dir(options.out);
    for (const Status& st :
         {writeTextFile((dir / "validation.md").string(), md),
          writeJsonFile((dir / "validation.json").string(), validationJson(plan, result))})
        if (!st)
            fmt::print(err, "qvr validate: {}\n", st.error());
    fmt::print(out, "  wrote {}/validation.md and validation.json\n", options.out);
    if (result.stop_signal != 0)
        fmt::print(err, "qvr validate: stopped by signal {}\n", result.stop_signal);
    return validationExitCode(result);
}

}  // namespace qvr::experiment
