#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "qvr/experiment/validation.h"

namespace qvr::experiment {
namespace {

using nlohmann::json;

// Answers every command from `respond`, starts nothing; `stop_after` commands in, a signal.
class FakeRunner final : public ChildRunner {
public:
    std::function<ChildOutcome(const ChildCommand&)> respond;
    std::vector<ChildCommand> commands;
    size_t stop_after = 0;  // 0: never

    ChildOutcome run(const ChildCommand& command) override {
        commands.push_back(command);
        if (commands.size() == stop_after)
            m_stop = 2;
        return respond(command);
    }
    int stopSignal() const override { return m_stop; }
    size_t count(const std::string& part) const {
        size_t n = 0;
        for (const ChildCommand& c : commands)
            n += c.line.find(part) != std::string::npos;
        return n;
    }

private:
    int m_stop = 0;
};

bool isCalibration(const ChildCommand& c) {
    return c.line.find(" calibrate ") != std::string::npos;
}

// A run's summary: one design, its FPS error, its probes `disturbance_pct` from steady.
json runSummary(double fps_error_pct, double disturbance_pct) {
    json s = {{"designs", {{"qvr", {{"prediction_error_pct", {{"fps_mean", fps_error_pct}}}}}}}};
    s["calibration"]["speed_reference"] = {
        {"run_spread_pct", {{"headset", disturbance_pct}, {"server", 0.0}}},
        {"run_over_reference", {{"headset", 1.0}, {"server", 1.0}}}};
    return s;
}

ChildOutcome ok(json result) {
    return {0, std::move(result)};
}

// Every calibration steady, every run steady with a 5% FPS error.
ChildOutcome steady(const ChildCommand& c) {
    return isCalibration(c) ? ok(json::object()) : ok(runSummary(5.0, 2.0));
}

ValidationPlan plan(int reps, CalibrationPolicy policy, int retakes = 1) {
    ValidationOptions o;
    o.executable = "qvr";
    o.links = {"wifi", "lte"};
    o.scenes = {"room"};
    o.depths = {1};
    o.reps = reps;
    o.retakes = retakes;
    o.calibrate = policy;
    o.out = "out";
    return planValidation(o);
}

std::FILE* sink() {
    static std::FILE* f = std::fopen("/dev/null", "w");
    return f;
}

ValidationResult execute(const ValidationPlan& p, FakeRunner& runner) {
    return executeValidation(p, runner, sink(), sink());
}

TEST(ValidationRun, EachRepetitionsRunsUseItsOwnCalibration) {
    FakeRunner runner;
    runner.respond = steady;
    const ValidationResult r = execute(plan(2, CalibrationPolicy::kPerRep), runner);
    ASSERT_EQ(runner.commands.size(), 6u);  // calibrate, 2 runs, calibrate, 2 runs
    EXPECT_TRUE(isCalibration(runner.commands[0]));
    EXPECT_TRUE(isCalibration(runner.commands[3]));
    EXPECT_NE(runner.commands[2].line.find("--hardware 'out/calibration-room.toml'"),
              std::string::npos);
    EXPECT_NE(runner.commands[5].line.find("--hardware 'out/calibration-room-r2.toml'"),
              std::string::npos);
    EXPECT_EQ(r.runs_counted, 4u);
    EXPECT_EQ(r.runs_steady, 4u);
    EXPECT_EQ(r.calibrations.size(), 2u);
    EXPECT_EQ(r.calibrations[1].rep, 2);
    EXPECT_EQ(r.rows.rows().size(), 2u);  // wifi and lte, two repetitions each
    EXPECT_EQ(r.rows.rows()[0].fps_error_pct.size(), 2u);
    EXPECT_EQ(validationExitCode(r), 0);
}

TEST(ValidationRun, OnceCalibratesOnceForEveryRepetition) {
    FakeRunner runner;
    runner.respond = steady;
    const ValidationResult r = execute(plan(3, CalibrationPolicy::kOnce), runner);
    EXPECT_EQ(runner.count(" calibrate "), 1u);
    EXPECT_EQ(runner.count("--hardware 'out/calibration-room.toml'"), 6u);
    ASSERT_EQ(r.calibrations.size(), 1u);
    EXPECT_EQ(r.calibrations[0].rep, 0);
}

TEST(ValidationRun, AnUnsteadyRunIsTakenAgainAndTheSteadiestCounts) {
    FakeRunner runner;
    runner.respond = [](const ChildCommand& c) {
        if (isCalibration(c))
            return ok(json::object());
        const bool retake = c.output.find("_t2") != std::string::npos;
        // wifi: 20% then 5% from steady; lte: 30% then 40%, both unsteady.
        if (c.output.find("wifi") != std::string::npos)
            return ok(retake ? runSummary(7.0, 5.0) : runSummary(-50.0, 20.0));
        return ok(retake ? runSummary(1.0, 40.0) : runSummary(3.0, 30.0));
    };
    const ValidationResult r = execute(plan(1, CalibrationPolicy::kPerRep), runner);
    EXPECT_EQ(runner.commands.size(), 5u);
    EXPECT_EQ(r.runs_retaken, 2);
    EXPECT_EQ(r.runs_unsteady_after_retakes, 1);  // lte
    EXPECT_EQ(r.runs_counted, 2u);
    EXPECT_EQ(r.runs_steady, 1u);  // wifi's second take
    ASSERT_EQ(r.rows.rows().size(), 2u);
    EXPECT_EQ(r.rows.rows()[0].fps_error_pct, std::vector<double>{7.0});
    EXPECT_EQ(r.rows.rows()[1].fps_error_pct, std::vector<double>{3.0});  // lte's first, 30%
    EXPECT_EQ(r.rows_first_takes.rows()[0].fps_error_pct, std::vector<double>{-50.0});
    EXPECT_EQ(r.run_disturbance_pct, (std::vector<double>{5.0, 30.0}));
}

TEST(ValidationRun, AnUnsteadyCalibrationIsTakenAgain) {
    FakeRunner runner;
    auto probes = [](double h2) {
        return json{{"speed_reference",
                     {{"probes",
                       {{{"headset_frame_ms", 10.0}, {"server_frame_ms", 20.0}},
                        {{"headset_frame_ms", h2}, {"server_frame_ms", 20.0}}}}}}};
    };
    runner.respond = [&](const ChildCommand& c) {
        if (!isCalibration(c))
            return ok(runSummary(5.0, 2.0));
        return ok(c.output.find("-t2") != std::string::npos ? probes(10.5) : probes(13.0));
    };
    const ValidationResult r = execute(plan(1, CalibrationPolicy::kOnce), runner);
    EXPECT_EQ(runner.count(" calibrate "), 2u);
    ASSERT_EQ(r.calibrations.size(), 1u);
    EXPECT_EQ(r.calibrations[0].file, "out/calibration-room-t2.toml");
    EXPECT_NEAR(r.calibrations[0].probe_spread_pct, 5.0, 1e-9);
    EXPECT_EQ(runner.count("--hardware 'out/calibration-room-t2.toml'"), 2u);
}

TEST(ValidationRun, AStopEndsTheSheetAndStartsNothingMore) {
    FakeRunner runner;
    runner.respond = steady;
    runner.stop_after = 2;  // during the first run
    const ValidationResult r = execute(plan(2, CalibrationPolicy::kPerRep), runner);
    EXPECT_EQ(runner.commands.size(), 2u);
    EXPECT_EQ(r.stop_signal, 2);
    EXPECT_EQ(r.runs_counted, 0u);
    EXPECT_EQ(validationExitCode(r), 130);
}

TEST(ValidationRun, AFailedRepetitionsCalibrationSkipsItsRuns) {
    FakeRunner runner;
    runner.respond = [](const ChildCommand& c) {
        if (c.output.find("-r2") != std::string::npos)
            return ChildOutcome{1, {}};
        return steady(c);
    };
    const ValidationResult r = execute(plan(2, CalibrationPolicy::kPerRep), runner);
    EXPECT_EQ(runner.commands.size(), 4u);  // rep 2's runs never start
    EXPECT_EQ(r.failed_runs, 1);
    EXPECT_EQ(r.runs_counted, 2u);
    EXPECT_EQ(validationExitCode(r), 1);
}

TEST(ValidationRun, BadInputOrAFailedSharedCalibrationEndsTheSheet) {
    FakeRunner refused;
    refused.respond = [](const ChildCommand&) { return ChildOutcome{2, {}}; };
    EXPECT_EQ(execute(plan(2, CalibrationPolicy::kPerRep), refused).aborted_exit, 2);
    EXPECT_EQ(refused.commands.size(), 1u);
    FakeRunner failed;
    failed.respond = [](const ChildCommand&) { return ChildOutcome{1, {}}; };
    EXPECT_EQ(execute(plan(2, CalibrationPolicy::kOnce), failed).aborted_exit, 1);
    EXPECT_EQ(failed.commands.size(), 1u);
}

TEST(ValidationRun, AFailedRunIsCountedAndTheSheetGoesOn) {
    FakeRunner runner;
    runner.respond = [](const ChildCommand& c) {
        if (c.output.find("wifi") != std::string::npos)
            return ok(json::object());  // exit 0 but no designs
        return steady(c);
    };
    const ValidationResult r = execute(plan(1, CalibrationPolicy::kPerRep), runner);
    EXPECT_EQ(r.failed_runs, 1);
    EXPECT_EQ(r.runs_counted, 1u);
}

TEST(ValidationRun, ADryRunPrintsThePlanAndStartsNothing) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "qvr_val_dry";
    ValidationOptions o = plan(2, CalibrationPolicy::kPerRep).options;
    o.out = dir.string();
    o.dry_run = true;
    FakeRunner runner;
    std::FILE* out = std::tmpfile();
    ASSERT_NE(out, nullptr);
    EXPECT_EQ(runValidation(o, runner, out, sink()), 0);
    EXPECT_TRUE(runner.commands.empty());
    std::rewind(out);
    std::string text;
    for (int ch; (ch = std::fgetc(out)) != EOF;)
        text += static_cast<char>(ch);
    std::fclose(out);
    EXPECT_EQ(text.rfind("qvr validate: 2 conditions (2 links × 1 scenes × 1 depths) × 2 "
                         "repetition(s)",
                         0),
              0u)
        << text;
    const size_t cal2 = text.find("  calibrating on room for rep 2 ...\n");
    ASSERT_NE(cal2, std::string::npos) << text;
    EXPECT_LT(text.find("  room | lte | depth 1 | rep 1 ...\n"), cal2);
    EXPECT_NE(text.find("calibration-room-r2.toml' --no-video", cal2), std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST(ValidationRun, TheSheetIsWrittenFromTheResult) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "qvr_val_sheet";
    ValidationOptions o = plan(1, CalibrationPolicy::kOnce).options;
    o.out = dir.string();
    FakeRunner runner;
    runner.respond = steady;
    EXPECT_EQ(runValidation(o, runner, sink(), sink()), 0);
    std::ifstream f(dir / "validation.json");
    const json j = json::parse(f, nullptr, false);
    ASSERT_TRUE(j.is_object());
    EXPECT_EQ(j["calibrate"], "once");
    EXPECT_DOUBLE_EQ(j["fps_abs_error_pct_mean"].get<double>(), 5.0);
    EXPECT_EQ(j["rows"].size(), 2u);
    EXPECT_TRUE(std::filesystem::exists(dir / "validation.md"));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace qvr::experiment
