// `qvr control` as a function (controller/control_report.h): the workload from its names, the
// link's effective rate, the run beside the oracle and the comparison, and both reports.
#include "qvr/controller/control_report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "qvr/core/link_efficiency.h"

namespace qvr {
namespace {

TEST(ControlReport, NamesTheSuiteWhenTheBenchIsUnknown) {
    auto bad = controlWorkload("", "synthetic-nope", 10);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("unknown --bench 'synthetic-nope'"), std::string::npos);
    EXPECT_NE(bad.error().find("synthetic-grid"), std::string::npos);
    auto def = controlWorkload("", "", 12);
    ASSERT_TRUE(def);
    EXPECT_EQ(def->frames.size(), 12u);
    EXPECT_EQ(def->header.name, "synthetic-default");
}

TEST(ControlReport, EffectiveThroughputIsNominalTimesTheTable1Efficiency) {
    const double eta = calibratedLinkEfficiency();
    EXPECT_DOUBLE_EQ(*effectiveThroughputMbps("wifi"), 200.0 * eta);
    EXPECT_DOUBLE_EQ(*effectiveThroughputMbps("lte"), 100.0 * eta);
    EXPECT_DOUBLE_EQ(*effectiveThroughputMbps("5g"), 500.0 * eta);
    EXPECT_FALSE(effectiveThroughputMbps("none"));
    EXPECT_FALSE(effectiveThroughputMbps("dialup"));
}

TEST(ControlReport, MeasuresThePolicyAgainstTheOracleAndComparesAll) {
    auto trace = controlWorkload("", "", 60);
    ASSERT_TRUE(trace);
    ControlPlan plan;
    plan.frames = 60;
    plan.throughput_mbps = *effectiveThroughputMbps("wifi");
    plan.compare = true;
    auto r = runControl(*trace, plan);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->run.policy, "liwc");
    EXPECT_EQ(r->run.frames.size(), 60u);
    ASSERT_EQ(r->compared.size(), 4u);
    EXPECT_EQ(r->compared[3].first, "oracle");
    EXPECT_DOUBLE_EQ(r->compared[3].second.frame_ms_mean, r->oracle.frame_ms_mean);
    // The oracle knows each frame's true cost: no policy beats it on the mean frame time.
    EXPECT_GE(r->run.summary.frame_ms_mean, r->oracle.frame_ms_mean * (1.0 - 1e-9));
    EXPECT_GT(r->local_only_ms_mean, 0.0);
    const std::string text = controlReportText(*r);
    EXPECT_NE(text.find("policy liwc: frame by frame (every 20th)"), std::string::npos);
    EXPECT_NE(text.find("  oracle  frame"), std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(controlReportJson(*r));
    EXPECT_EQ(j["frames"].size(), 60u);
    EXPECT_EQ(j["compare"].size(), 4u);
    EXPECT_DOUBLE_EQ(j["summary"]["oracle_frame_ms_mean"].get<double>(), r->oracle.frame_ms_mean);
}

TEST(ControlReport, RefusesAnUnknownPolicy) {
    auto trace = controlWorkload("", "", 5);
    ControlPlan plan;
    plan.policy = "bogus";
    plan.throughput_mbps = 100.0;
    EXPECT_FALSE(runControl(*trace, plan));
}

}  // namespace
}  // namespace qvr
