#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "qvr/experiment/validation.h"

namespace qvr::experiment {
namespace {

using nlohmann::json;

// A design's entry of a run's summary.json with the prediction's errors.
json design(double fps_error_pct, double mtp_error_pct = 2.0) {
    return {{"fps_mean", 60.0},
            {"predicted", {{"fps_mean", 55.0}}},
            {"prediction_error_pct",
             {{"fps_mean", fps_error_pct},
              {"mtp_ms_mean", mtp_error_pct},
              {"bytes_per_frame_mean", -3.0},
              {"headset_busy_ms_mean", 4.0},
              {"server_busy_ms_mean", -6.0}}},
            {"prediction_error_abs", {{"e1_deg_mean", 0.5}}}};
}

json summaryOf(json designs) {
    return {{"designs", std::move(designs)}};
}

// A summary whose speed probes spread `spread_pct` across the run and averaged `over` times the
// calibration's reference.
json probed(json summary, double spread_pct, double over) {
    summary["calibration"]["speed_reference"] = {
        {"run_spread_pct", {{"headset", spread_pct}, {"server", 1.0}}},
        {"run_over_reference", {{"headset", 1.0}, {"server", over}}}};
    return summary;
}

TEST(ValidationRows, ReadEveryDesignWithAPrediction) {
    ValidationRows rows;
    rows.add(summaryOf({{"qvr", design(8.0)}, {"local", {{"fps_mean", 90.0}}}}), "room", "wifi", 2);
    ASSERT_EQ(rows.rows().size(), 1u);
    const ValidationRow& r = rows.rows()[0];
    EXPECT_EQ(r.design, "qvr");
    EXPECT_EQ(r.depth, 2);
    EXPECT_EQ(r.fps_error_pct, std::vector<double>{8.0});
    EXPECT_EQ(r.fps_measured, std::vector<double>{60.0});
    EXPECT_EQ(r.fps_predicted, std::vector<double>{55.0});
    EXPECT_EQ(r.e1_error_deg, std::vector<double>{0.5});
    EXPECT_EQ(r.server_cost_error_pct, std::vector<double>{-6.0});
    EXPECT_TRUE(r.fps_error_pct_at_probe_speed.empty());
    // A second repetition of the condition lands in the same cell.
    json again = summaryOf({{"qvr", design(-2.0)}});
    again["designs"]["qvr"]["prediction_error_pct_at_probe_speed"] = {{"fps_mean", 1.5}};
    rows.add(again, "room", "wifi", 2);
    ASSERT_EQ(rows.rows().size(), 1u);
    EXPECT_EQ(rows.rows()[0].fps_error_pct, (std::vector<double>{8.0, -2.0}));
    EXPECT_EQ(rows.rows()[0].fps_error_pct_at_probe_speed, std::vector<double>{1.5});
    rows.add(again, "room", "wifi", 1);
    EXPECT_EQ(rows.rows().size(), 2u);
}

TEST(ValidationRows, AMissingFieldReadsAsNaN) {
    ValidationRows rows;
    rows.add(summaryOf({{"ffr", {{"prediction_error_pct", json::object()}}}}), "s", "l", 1);
    ASSERT_EQ(rows.rows().size(), 1u);
    EXPECT_TRUE(std::isnan(rows.rows()[0].fps_error_pct[0]));
    EXPECT_TRUE(std::isnan(rows.rows()[0].e1_error_deg[0]));
    rows.add(json::object(), "s", "l", 1);  // no designs at all
    EXPECT_EQ(rows.rows().size(), 1u);
}

TEST(ValidationStats, MeanAbsoluteAndWorstOverTheCellsMeans) {
    ValidationResult result;
    // Cell ffr (read first): −2 twice; cell qvr: +20 then −4 (mean +8).
    result.rows.add(summaryOf({{"qvr", design(20.0)}, {"ffr", design(-2.0)}}), "s", "l", 1);
    result.rows.add(summaryOf({{"qvr", design(-4.0)}, {"ffr", design(-2.0)}}), "s", "l", 1);
    ASSERT_EQ(result.rows.rows()[0].design, "ffr");
    const ValidationStats s = summariseValidation(result);
    EXPECT_DOUBLE_EQ(s.fps.mean, 5.0);
    EXPECT_DOUBLE_EQ(s.fps.worst, 8.0);
    EXPECT_EQ(s.fps.cells, 2u);
    EXPECT_DOUBLE_EQ(s.bytes.mean, 3.0);
    EXPECT_TRUE(std::isnan(s.fps_at_probe_speed.mean));  // no cell has it
    EXPECT_EQ(s.fps_at_probe_speed.cells, 0u);
    EXPECT_TRUE(std::isnan(s.fps_steady.worst));  // no steady run
}

TEST(ValidationStats, FirstTakesAndSteadyRunsAreReadInTheSheetsCells) {
    ValidationResult result;
    result.rows.add(summaryOf({{"qvr", design(1.0)}, {"sw", design(2.0)}}), "s", "l", 1);
    result.rows_first_takes.add(summaryOf({{"qvr", design(-30.0)}}), "s", "l", 1);
    // A cell the sheet does not have is not counted.
    result.rows_steady.add(summaryOf({{"qvr", design(4.0, 7.0)}}), "s", "l", 2);
    result.rows_steady.add(summaryOf({{"sw", design(6.0, -9.0)}}), "s", "l", 1);
    const ValidationStats s = summariseValidation(result);
    EXPECT_DOUBLE_EQ(s.fps_first_takes.mean, 30.0);
    EXPECT_EQ(s.fps_first_takes.cells, 1u);
    EXPECT_DOUBLE_EQ(s.fps_steady.mean, 6.0);
    EXPECT_DOUBLE_EQ(s.mtp_steady.worst, 9.0);
    EXPECT_EQ(s.fps_steady.cells, 1u);
}

TEST(ValidationStats, MedianSpreadAndUnsteadyRuns) {
    ValidationResult result;
    result.run_speed_spread_pct = {12.0, 3.0, 30.0, 5.0};
    const ValidationStats s = summariseValidation(result);
    EXPECT_DOUBLE_EQ(s.run_speed_spread_median_pct, 12.0);  // the upper of the middle two
    EXPECT_EQ(s.runs_unsteady, 2u);
    EXPECT_TRUE(std::isnan(summariseValidation(ValidationResult{}).run_speed_spread_median_pct));
}

TEST(ValidationSteadiness, ARunsDisturbanceIsItsLargestMoveEitherSide) {
    EXPECT_TRUE(std::isnan(runDisturbancePct(summaryOf(json::object()))));  // no probes
    EXPECT_DOUBLE_EQ(runDisturbancePct(probed(summaryOf(json::object()), 12.0, 0.95)), 12.0);
    EXPECT_NEAR(runDisturbancePct(probed(summaryOf(json::object()), 3.0, 1.2)), 20.0, 1e-9);
    EXPECT_DOUBLE_EQ(runSpeedSpreadPct(probed(summaryOf(json::object()), 12.0, 0.95)), 12.0);
    EXPECT_TRUE(std::isnan(runSpeedSpreadPct(summaryOf(json::object()))));
}

TEST(ValidationSteadiness, ProbesWithinTenPercentOrAbsentAreSteady) {
    EXPECT_TRUE(steadyByProbes(NAN));
    EXPECT_TRUE(steadyByProbes(10.0));
    EXPECT_FALSE(steadyByProbes(10.5));
    EXPECT_TRUE(steadierTake(4.0, 5.0));
    EXPECT_FALSE(steadierTake(5.0, 5.0));  // the earlier take keeps its place
    EXPECT_FALSE(steadierTake(6.0, 5.0));
    EXPECT_TRUE(steadierTake(NAN, 5.0));
    EXPECT_TRUE(steadierTake(30.0, INFINITY));
    EXPECT_EQ(takeNote(NAN, true), "");
    EXPECT_EQ(takeNote(4.0, true), " (speed moved 4%)");
    EXPECT_EQ(takeNote(14.0, true), " (speed moved 14%: unsteady, again)");
    EXPECT_EQ(takeNote(14.0, false), " (speed moved 14%: unsteady)");
}

TEST(ValidationSteadiness, ACalibrationsSpreadIsItsProbesLargestSpread) {
    auto probe = [](double h, double s) {
        return json{{"headset_frame_ms", h}, {"server_frame_ms", s}};
    };
    json cal = {{"speed_reference", {{"probes", {probe(10, 20), probe(11, 20), probe(10, 21)}}}}};
    EXPECT_NEAR(calibrationSpreadPct(cal), 10.0, 1e-9);
    cal["speed_reference"]["probes"] = {probe(10, 20)};
    EXPECT_TRUE(std::isnan(calibrationSpreadPct(cal)));  // one probe tells nothing
    cal["speed_reference"]["probes"] = {probe(10, 20), probe(0, 20)};
    EXPECT_TRUE(std::isnan(calibrationSpreadPct(cal)));
    EXPECT_TRUE(std::isnan(calibrationSpreadPct(json::parse("{", nullptr, false))));
}

ValidationPlan onePlan() {
    ValidationOptions o;
    o.links = {"wifi"};
    o.scenes = {"room"};
    o.depths = {1};
    o.reps = 2;
    o.retakes = 1;
    return planValidation(o);
}

ValidationResult handMade() {
    ValidationResult result;
    result.machine = "2 × Test CPU";
    result.seconds = 61.6;
    json a = summaryOf({{"qvr", design(10.0)}});
    json b = summaryOf({{"qvr", design(-4.0)}});
    b["designs"]["qvr"]["fps_mean"] = 64.0;
    b["designs"]["qvr"]["prediction_error_abs"] = json::object();
    result.rows.add(a, "room", "trace:/x/ATT.down", 1);
    result.rows.add(b, "room", "trace:/x/ATT.down", 1);
    result.rows_first_takes = result.rows;
    result.runs_counted = 2;
    result.runs_retaken = 1;
    result.failed_runs = 1;
    result.calibrations = {{"room", 1, "cal.toml", 3.5}, {"room", 2, "cal-r2.toml", NAN}};
    result.run_speed_spread_pct = {4.0, 12.0};
    result.run_disturbance_pct = {4.0, 12.0};
    return result;
}

TEST(ValidationSheet, TheTableHasARowPerCell) {
    const std::string md = validationMarkdown(onePlan(), handMade());
    // Measured 60 and 64 (spread 4), errors +10 and −4; e1 is NaN in one repetition.
    EXPECT_NE(md.find("| room | trace:ATT.down | 1 | qvr | 62.0 | 55.0 | +3.0% | +2.0% | -3.0% | "
                      "— | 4.0 | +4.0% | -6.0% |\n"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("Mean absolute error (worst): FPS 3.0% (3.0%), MTP mean 2.0% (2.0%), "
                      "bytes/frame 3.0% (3.0%), e1 — (—) over 1 design × condition cells; 1 "
                      "failed runs; 62 s.\n"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("The steady runs alone (0 of 2: "), std::string::npos) << md;
    EXPECT_NE(md.find("): 1 (up to 1 per run); still unsteady after them: 0 of 2. The first "
                      "takes alone: FPS 3.0% (3.0%).\n"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("moved by a median 12.0% over a run, over 10% in 1 of 2 runs.\n"),
              std::string::npos)
        << md;
    EXPECT_EQ(md.find("Stopped by a signal"), std::string::npos);
    ValidationResult stopped = handMade();
    stopped.stop_signal = 2;
    EXPECT_NE(validationMarkdown(onePlan(), stopped)
                  .find("Stopped by a signal: the sheet has the 2 runs that ended of 2.\n"),
              std::string::npos);
}

TEST(ValidationSheet, TheJsonCarriesTheRowsAndAggregates) {
    const json j = validationJson(onePlan(), handMade());
    EXPECT_EQ(j["machine"], "2 × Test CPU");
    EXPECT_EQ(j["calibrate"], "per-rep");
    EXPECT_EQ(j["reps"], 2);
    EXPECT_EQ(j["failed_runs"], 1);
    EXPECT_DOUBLE_EQ(j["fps_abs_error_pct_mean"].get<double>(), 3.0);
    EXPECT_EQ(j["runs_unsteady"], 1);
    EXPECT_EQ(j["calibrations"][1]["file"], "cal-r2.toml");
    EXPECT_EQ(j["calibrations"][1]["rep"], 2);
    EXPECT_EQ(j["calibration_probe_spread_pct"].size(), 2u);
    ASSERT_EQ(j["rows"].size(), 1u);
    EXPECT_EQ(j["rows"][0]["link"], "trace:/x/ATT.down");
    EXPECT_EQ(j["rows"][0]["fps_error_pct"], json({10.0, -4.0}));
    // NaN means are null in the file.
    EXPECT_EQ(j.dump().find("NaN"), std::string::npos);
    EXPECT_TRUE(json::parse(j.dump())["e1_abs_error_deg_mean"].is_null());
}

TEST(ValidationSheet, ExitStatus) {
    ValidationResult r;
    EXPECT_EQ(validationExitCode(r), 0);
    r.failed_runs = 1;
    EXPECT_EQ(validationExitCode(r), 1);
    r.stop_signal = 15;
    EXPECT_EQ(validationExitCode(r), 130);
    r.aborted_exit = 2;
    EXPECT_EQ(validationExitCode(r), 2);
}

}  // namespace
}  // namespace qvr::experiment

namespace qvr::experiment {
namespace {

TEST(ValidationStats, EveryRunsErrorBesideTheCellsMeans) {
    ValidationResult result;
    // One cell: +20 then −4 (mean +8); the same scene at another motion and share is its own.
    result.rows.add(summaryOf({{"fixed:10", design(20.0)}}), "s", "l", 2);
    result.rows.add(summaryOf({{"fixed:10", design(-4.0)}}), "s", "l", 2);
    result.rows.add(summaryOf({{"fixed:10", design(30.0)}}), "s", "l", 2, "/m/01_03.bvh", 0.5);
    ASSERT_EQ(result.rows.rows().size(), 2u);
    EXPECT_EQ(result.rows.rows()[1].headset_share, 0.5);
    const ValidationStats s = summariseValidation(result);
    EXPECT_DOUBLE_EQ(s.fps.worst, 30.0);
    EXPECT_DOUBLE_EQ(s.fps.mean, 19.0);  // (8 + 30) / 2 over cells
    EXPECT_EQ(s.fps_every_run.cells, 3u);
    EXPECT_DOUBLE_EQ(s.fps_every_run.mean, 18.0);  // (20 + 4 + 30) / 3 over runs
    ValidationPlan plan;
    const std::string md = validationMarkdown(plan, result);
    EXPECT_NE(md.find("Every run on its own (not a cell's mean over repetitions): FPS 18.0% "
                      "(30.0%) over 3 runs."),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| s | l | 2 | fixed:10 | 2 | 60.0 | 55.0 | -4.0% |"), std::string::npos)
        << md;
    EXPECT_NE(md.find("| s · 01_03 · share 0.5 | l | 2 | fixed:10 | 1 |"), std::string::npos) << md;
    const json j = validationJson(plan, result);
    EXPECT_DOUBLE_EQ(j["fps_abs_error_pct_worst_every_run"].get<double>(), 30.0);
    EXPECT_EQ(j["rows"][1]["motion"], "/m/01_03.bvh");
}

}  // namespace
}  // namespace qvr::experiment
