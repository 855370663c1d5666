#include <gtest/gtest.h>

#include "qvr/experiment/validation.h"

namespace qvr::experiment {
namespace {

ValidationOptions twoScenes(int reps, CalibrationPolicy policy) {
    ValidationOptions o;
    o.executable = "/bin/qvr";
    o.links = {"wifi"};
    o.scenes = {"builtin:room", "openarena:oa_dm5"};
    o.depths = {1, 2};
    o.reps = reps;
    o.calibrate = policy;
    o.out = "out";
    return o;
}

TEST(ValidationPlan, PerRepCalibratesEachSceneForEachRepetitionBeforeItsRuns) {
    const ValidationPlan plan = planValidation(twoScenes(2, CalibrationPolicy::kPerRep));
    EXPECT_EQ(plan.policy, CalibrationPolicy::kPerRep);
    ASSERT_EQ(plan.calibrations.size(), 4u);  // 2 scenes × 2 repetitions
    ASSERT_EQ(plan.runs.size(), 8u);          // 1 link × 2 scenes × 2 depths × 2 repetitions
    EXPECT_EQ(plan.conditions(), 4u);
    ASSERT_EQ(plan.steps.size(), 12u);
    // Each calibration, then that scene's runs of that repetition.
    for (size_t s = 0; s < plan.steps.size(); s += 3) {
        ASSERT_EQ(plan.steps[s].kind, PlannedStep::Kind::kCalibration) << s;
        const PlannedCalibration& c = plan.calibrations[plan.steps[s].index];
        EXPECT_EQ(c.rep, static_cast<int>(s / 6));
        EXPECT_EQ(c.scene, twoScenes(1, {}).scenes[(s / 3) % 2]);
        for (size_t k = 1; k <= 2; ++k) {
            ASSERT_EQ(plan.steps[s + k].kind, PlannedStep::Kind::kRun);
            const PlannedRun& r = plan.runs[plan.steps[s + k].index];
            EXPECT_EQ(r.calibration, plan.steps[s].index);
            EXPECT_EQ(r.scene, c.scene);
            EXPECT_EQ(r.rep, c.rep);
            EXPECT_EQ(r.depth, static_cast<int>(k));
        }
    }
}

TEST(ValidationPlan, OnceCalibratesEachSceneOnceBeforeAnyRun) {
    const ValidationPlan plan = planValidation(twoScenes(2, CalibrationPolicy::kOnce));
    EXPECT_EQ(plan.policy, CalibrationPolicy::kOnce);
    ASSERT_EQ(plan.calibrations.size(), 2u);
    ASSERT_EQ(plan.runs.size(), 8u);
    EXPECT_EQ(plan.steps[0].kind, PlannedStep::Kind::kCalibration);
    EXPECT_EQ(plan.steps[1].kind, PlannedStep::Kind::kCalibration);
    for (size_t s = 2; s < plan.steps.size(); ++s)
        EXPECT_EQ(plan.steps[s].kind, PlannedStep::Kind::kRun) << s;
    for (const PlannedRun& r : plan.runs)
        EXPECT_EQ(plan.calibrations[r.calibration].scene, r.scene);
    EXPECT_EQ(plan.runs.back().rep, 1);
    EXPECT_EQ(plan.calibrations[0].rep, 0);
    EXPECT_EQ(plan.calibrations[1].rep, 0);
}

TEST(ValidationPlan, AGivenCalibrationServesEveryRepetition) {
    ValidationOptions o = twoScenes(3, CalibrationPolicy::kPerRep);
    o.scenes = {"builtin:room"};
    o.hardware = "/cal.toml";
    const ValidationPlan plan = planValidation(o);
    EXPECT_EQ(plan.policy, CalibrationPolicy::kGiven);
    EXPECT_EQ(plan.calibrations.size(), 1u);
    EXPECT_EQ(plan.runs.size(), 6u);
    EXPECT_STREQ(calibrationPolicyName(plan.policy), "hardware");
    EXPECT_STREQ(calibrationPolicyName(CalibrationPolicy::kPerRep), "per-rep");
    EXPECT_STREQ(calibrationPolicyName(CalibrationPolicy::kOnce), "once");
}

TEST(ValidationPlan, CalibrationTakesNameTheirRepetitionAndTake) {
    const ValidationPlan plan = planValidation(twoScenes(2, CalibrationPolicy::kPerRep));
    const ChildCommand first = calibrationTake(plan, 0, 0);
    EXPECT_EQ(first.output, "out/calibration-builtin_room.toml");
    EXPECT_EQ(first.result_path, "out/calibration-builtin_room.toml.json");
    EXPECT_EQ(first.log_path, "out/calibration-builtin_room.toml.log");
    EXPECT_EQ(first.line,
              "'/bin/qvr' calibrate --scene 'builtin:room' --profile 'default' --out "
              "'out/calibration-builtin_room.toml' > 'out/calibration-builtin_room.toml.log' 2>&1");
    // The third calibration: the first scene's, for the second repetition; its second take.
    EXPECT_EQ(calibrationTake(plan, 2, 1).output, "out/calibration-builtin_room-r2-t2.toml");
}

TEST(ValidationPlan, RunTakesCarryTheirConditionAndCalibration) {
    ValidationOptions o = twoScenes(1, CalibrationPolicy::kPerRep);
    o.profile = "it's";
    const ValidationPlan plan = planValidation(o);
    const ChildCommand cmd = runTake(plan, 1, 1, "cal.toml");
    EXPECT_EQ(cmd.output, "out/builtin_room_wifi_d2_r1_t2");
    EXPECT_EQ(cmd.result_path, "out/builtin_room_wifi_d2_r1_t2/summary.json");
    EXPECT_EQ(cmd.line,
              "'/bin/qvr' run --scene 'builtin:room' --net 'wifi' --pipeline 2 --designs "
              "'local,remote,ffr,sw,qvr' --frames 40 --profile 'it'\\''s' --hardware 'cal.toml' "
              "--no-video --out 'out/builtin_room_wifi_d2_r1_t2' > "
              "'out/builtin_room_wifi_d2_r1_t2.log' 2>&1");
}

TEST(ValidationPlan, ARunChildLogsBesideItsFolderAndReportsInIt) {
    const ChildCommand cmd = runChildIn("out/x");
    EXPECT_EQ(cmd.output, "out/x");
    EXPECT_EQ(cmd.log_path, "out/x.log");
    EXPECT_EQ(cmd.result_path, "out/x/summary.json");
    EXPECT_TRUE(cmd.line.empty());
}

TEST(ValidationPlan, ALongLinkKeepsItsLastFortyCharactersInTheFolderName) {
    ValidationOptions o = twoScenes(1, CalibrationPolicy::kOnce);
    o.links = {"trace:/a/very/long/path/to/the/shared/data/network/ATT-LTE-driving-2016.down"};
    const ValidationPlan plan = planValidation(o);
    EXPECT_EQ(runTake(plan, 0, 0, "c").output,
              "out/builtin_room_d_data_network_ATT-LTE-driving-2016_down_d1_r1");
}

}  // namespace
}  // namespace qvr::experiment

namespace qvr::experiment {
namespace {

TEST(ValidationPlan, OneSceneCalibratedPredictsEveryScenesMotionsAndShares) {
    ValidationOptions o = twoScenes(2, CalibrationPolicy::kPerRep);
    o.depths = {2};
    o.links = {"rate:2.5"};
    o.motions = {"default", "/m/01_03.bvh"};
    o.headset_shares = {1.0, 0.5};
    o.calibration_scene = "builtin:room";
    const ValidationPlan plan = planValidation(o);
    EXPECT_EQ(plan.conditions(), 8u);         // 2 scenes × 2 motions × 2 shares
    ASSERT_EQ(plan.calibrations.size(), 2u);  // the one scene, per repetition
    ASSERT_EQ(plan.runs.size(), 16u);
    for (const PlannedCalibration& c : plan.calibrations)
        EXPECT_EQ(c.scene, "builtin:room");
    for (const PlannedRun& r : plan.runs)
        EXPECT_EQ(plan.calibrations[r.calibration].rep, r.rep);
    EXPECT_EQ(plan.runs.back().scene, "openarena:oa_dm5");
    // A run away from the defaults says so in its command and folder.
    const PlannedRun& last = plan.runs[7];
    EXPECT_EQ(last.motion, "/m/01_03.bvh");
    EXPECT_EQ(last.headset_share, 0.5);
    const ChildCommand cmd = runTake(plan, 7, 0, "cal.toml");
    EXPECT_NE(cmd.line.find("--motion '/m/01_03.bvh'"), std::string::npos) << cmd.line;
    EXPECT_NE(cmd.line.find("--headset-share 0.5"), std::string::npos) << cmd.line;
    EXPECT_NE(cmd.output.find("_m01_03_s0.5_r1"), std::string::npos) << cmd.output;
    const ChildCommand first = runTake(plan, 0, 0, "cal.toml");
    EXPECT_EQ(first.line.find("--motion"), std::string::npos) << first.line;
    EXPECT_EQ(first.line.find("--headset-share"), std::string::npos) << first.line;
    o.calibrate = CalibrationPolicy::kOnce;
    EXPECT_EQ(planValidation(o).calibrations.size(), 1u);
}

}  // namespace
}  // namespace qvr::experiment
