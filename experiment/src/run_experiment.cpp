// `qvr run` as one call: its plan's calibration, the designs run, predicted and reported.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "qvr/experiment/run_experiment.h"

namespace qvr::experiment {

namespace {

std::string fmtCell(const std::optional<double>& v, const char* fmt_spec) {
    return v ? fmt::format(fmt::runtime(fmt_spec), *v) : "—";
}

// Each predicted design's errors on one line, by design name.
void printPredictionErrors(const RunOutcome& o) {
    fmt::print(
        "  calibrated prediction ({}): error of FPS, MTP mean, bytes/frame; e1; and of each "
        "side's own cost (headset busy per frame, server render+encode per served frame)\n",
        o.calibration.source);
    std::map<std::string, const DesignResult*> by_name;
    for (const DesignResult& d : o.designs)
        by_name[d.name] = &d;
    for (const auto& [name, d] : by_name) {
        if (!d->error)
            continue;
        const PredictionError& e = *d->error;
        const auto& speed = d->prediction.speed;
        fmt::print(
            "    {:8} fps {:>8}  mtp {:>8}  bytes {:>8}  e1 {:>7}  | headset {:>7}  server "
            "{:>7}  | speed x{} x{}: fps {:>7}\n",
            name, fmtCell(e.pctOf(Metric::kFps), "{:+.1f}%"),
            fmtCell(e.pctOf(Metric::kMtpMean), "{:+.1f}%"),
            fmtCell(e.pctOf(Metric::kBytes), "{:+.1f}%"), fmtCell(e.e1_deg_abs, "{:+.1f}°"),
            fmtCell(e.pctOf(Metric::kHeadsetBusy), "{:+.1f}%"),
            fmtCell(e.pctOf(Metric::kServerBusy), "{:+.1f}%"),
            fmtCell(speed ? std::optional(speed->headset) : std::nullopt, "{:.3f}"),
            fmtCell(speed ? std::optional(speed->server) : std::nullopt, "{:.3f}"),
            fmtCell(d->error_at_probe_speed ? d->error_at_probe_speed->pctOf(Metric::kFps)
                                            : std::nullopt,
                    "{:+.1f}%"));
    }
    const RunSpeed& s = o.speed;
    fmt::print("  speed: {}\n",
               o.speed_note.empty()
                   ? fmt::format("the probes around each design over the calibration's "
                                 "(headset, server), and the FPS error of the prediction with "
                                 "the design's costs at that speed (summary.json "
                                 "designs.<d>.speed, predicted_at_probe_speed); the probes "
                                 "moved {:.0f}% / {:.0f}% over the run",
                                 s.spread_pct[0], s.spread_pct[1])
                   : o.speed_note);
    if (s.unsteady)
        fmt::print(
            "  warning: the machine's speed moved by {:.0f}% during the run (the speed probes "
            "between designs, over {:.0f}%): a design's FPS moves with it within the seconds "
            "it runs, which no prediction made around it follows; measure on a steady "
            "machine to judge the model (summary.json calibration.speed_reference)\n",
            std::max(s.spread_pct[0], s.spread_pct[1]), kUnsteadySpeedPct);
}

}  // namespace

void printRunSummary(const RunOutcome& o, const std::string& out) {
    fmt::print("  ratios: {}\n", ratiosJson(headlineRatios(o.designs)).dump());
    bool predicted = false;
    for (const DesignResult& d : o.designs)
        predicted = predicted || d.prediction.calibrated.has_value();
    if (predicted)
        printPredictionErrors(o);
    const std::array<double, 2>& over = o.speed.over_reference;
    if (const double off = std::max(std::fabs(over[0] - 1.0), std::fabs(over[1] - 1.0));
        over[0] > 0.0 && off > 0.10)
        fmt::print(
            "  warning: this run's speed probes took x{:.2f} (headset) and x{:.2f} (server) the "
            "time the calibration's did: the machine is not as fast as when it was calibrated "
            "({}); `qvr run --recalibrate` measures it again\n",
            over[0], over[1], o.calibration.path);
    if (!o.sim_note.empty())
        fmt::print("  {}\n", o.sim_note);
    if (const HeadsetsResult* h = headlineHeadsets(o.headsets_by_design); h && o.headsets > 1)
        fmt::print(
            "  {} headsets ({}): FPS mean {:.1f}, min {:.1f}, Jain's index {:.3f}, server {} ms "
            "per headset-frame (summary.json headsets)\n",
            h->headsets.size(), h->design, h->fps_mean, h->fps_min, h->jain_fairness_fps,
            fmtCell(h->server_ms_per_headset_frame, "{:.2f}"));
    fmt::print(
        "  {}\n  {}\n  wrote {}/summary.json, telemetry.csv, frames_*.csv, report.html in {:.0f} "
        "s\n",
        o.video.note, o.trace_note, out, o.run_seconds);
}

int runExitStatus(const RunOutcome& o, const std::string& out) {
    if (o.interrupted) {
        std::fprintf(stderr, "qvr run: %s; wrote what was measured to %s\n",
                     o.interrupted_note.c_str(), out.c_str());
        return 130;
    }
    // Designs whose display the server's layers did not keep new: a failure, not a slow run.
    const std::pair<const std::vector<std::string>*, const char*> stale[] = {
        {&o.never_shown, "never showed a layer from the server (summary.json startup_unfinished)"},
        {&o.stale_only,
         "showed no server layers newer than its start-up's in its counted frames (summary.json "
         "frames_new_layers 0)"}};
    for (const auto& [designs, what] : stale)
        if (!designs->empty()) {
            std::fprintf(stderr, "qvr run: %s %s; wrote what was measured to %s\n",
                         fmt::format("{}", fmt::join(*designs, ", ")).c_str(), what, out.c_str());
            return 1;
        }
    return 0;
}

int runExperiment(const RunOptions& plan, const std::vector<DesignSpec>& designs,
                  const HmdProfile& profile) {
    const auto t_start = std::chrono::steady_clock::now();
    auto inputs = runtime::loadHeadsetInputs(plan.scene, plan.motion, plan.gaze, profile.refresh_hz,
                                             plan.frames, plan.seed);
    if (!inputs) {
        std::fprintf(stderr, "qvr run: %s\n", inputs.error().c_str());
        return 2;
    }
    auto calibration = chooseCalibration(plan);
    if (!calibration) {
        std::fprintf(stderr, "qvr run: %s\n", calibration.error().c_str());
        return 2;
    }
    fmt::print("qvr run: prediction uses {}\n", calibration->note);
    const RuntimeCosts& calibrated = calibration->hardware.runtime;
    auto measured = measureDesigns(plan, designs, profile, *inputs, calibrated);
    if (const auto* error = std::get_if<RunError>(&measured)) {
        std::fprintf(stderr, "qvr run: %s\n", error->message.c_str());
        return error->exit_status;
    }
    const RunMeasurement& m = std::get<RunMeasurement>(measured);
    const double run_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    const RunPrediction prediction = predictRun(plan, profile, *inputs, calibrated, m);
    RunOutcome outcome = runOutcome(plan, profile, inputs->scene->name, designs.size(),
                                    *calibration, m, prediction, DisplayVideo{}, run_s);
    outcome.video = writeDisplayVideo(plan, profile, m);
    writeRunReport(outcome, plan.out);
    printRunSummary(outcome, plan.out);
    return runExitStatus(outcome, plan.out);
}

}  // namespace qvr::experiment
