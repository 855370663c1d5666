// `qvr sim` and `qvr eval` as functions (sim/sim_run.h, sim/eval_setup.h): inputs from their
// names with errors for bad ones, the runtime pipeline's outputs, the printed reports.
#include "qvr/sim/sim_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "qvr/sim/benches.h"
#include "qvr/sim/eval_setup.h"

namespace qvr {
namespace {

namespace fs = std::filesystem;

TEST(SimRun, ResolvesTheWorkloadAndRefusesBadNames) {
    auto w = simWorkload("grid", "", 25, "auto");
    ASSERT_TRUE(w) << w.error();
    EXPECT_EQ(w->frames.size(), 25u);
    EXPECT_FALSE(simWorkload("doom9", "", 25, "auto"));
    EXPECT_FALSE(simWorkload("", "/nonexistent/trace.jsonl", 25, "auto"));
    EXPECT_FALSE(simWorkload("grid", "", 25, "h265"));
    EXPECT_TRUE(simHardware("", 400.0));
    EXPECT_FALSE(simHardware("/nonexistent/hw.toml", 400.0));
}

TEST(SimRun, WritesTheRuntimePipelinesFramesAndSummary) {
    RuntimeRunResult run;
    run.frames.resize(2);
    run.frames[1].index = 1;
    run.frames[1].served = true;
    run.summary.design = "qvr";
    run.summary.frames = 2;
    run.summary.requests_dropped = 1;
    run.summary.requests_withheld = 5;
    const fs::path out =
        fs::temp_directory_path() / ("qvr-simrun-" + std::to_string(getpid())) / "deeper";
    ASSERT_TRUE(writeRuntimeSimOutputs(out, run, {"lte", 1, 250.0, 2}));
    std::ifstream in(out / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["pipeline"], "runtime");
    EXPECT_EQ(j["net"], "lte");
    EXPECT_EQ(j["pipeline_depth"], 1);
    EXPECT_EQ(j["requests_dropped"], 1);
    EXPECT_EQ(j["requests_withheld"], 5);
    EXPECT_EQ(j["frames"], 2);
    EXPECT_EQ(j.size(), 18u);
    std::ifstream csv(out / "frames.csv");
    int lines = 0;
    for (std::string line; std::getline(csv, line);)
        ++lines;
    EXPECT_EQ(lines, 3);
    const std::string report =
        runtimeSimReport(run.summary, "b", {"lte", 1, 250.0, 2}, out.string());
    EXPECT_EQ(report.rfind("qvr on b | runtime pipeline, 1 in flight | lte | 2 frames\n", 0), 0u);
    fs::remove_all(out.parent_path());
}

TEST(SimRun, TheRuntimePipelineRefusesTheStaticDesignAndABadLink) {
    auto w = simWorkload("grid", "", 20, "auto");
    ASSERT_TRUE(w);
    const HardwareConfig hw = defaultHardware(500.0);
    auto st = simulateRuntimePipeline(*w, Design::Static, hw, {"wifi", 2, 250.0, 20});
    ASSERT_FALSE(st);
    EXPECT_EQ(st.error(), "the runtime pipeline has no static design");
    auto bad = simulateRuntimePipeline(*w, Design::Qvr, hw, {"dialup", 2, 250.0, 20});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().rfind("--net: ", 0), 0u);
    auto run = simulateRuntimePipeline(*w, Design::Qvr, hw, {"wifi", 2, 250.0, 20});
    ASSERT_TRUE(run) << run.error();
    EXPECT_EQ(run->frames.size(), 20u);
}

TEST(EvalSetup, RefusesAnUnknownSuiteAndBench) {
    EvalInputs in;
    in.suite = "bogus";
    in.workloads = "/nonexistent";
    auto st = selectEvalSuite(in);
    ASSERT_FALSE(st);
    EXPECT_EQ(st.error(), "--suite must be auto, recorded or synthetic, got 'bogus'");
    in.suite = "synthetic";
    ASSERT_TRUE(selectEvalSuite(in));
    EXPECT_EQ(selectedSuite(), SuiteKind::kSynthetic);
    in.benches = {"doom9"};
    EXPECT_FALSE(evalCodecModel(in));
    in.benches = {};
    in.codec_model = "stream";
    auto codec = evalCodecModel(in);
    ASSERT_TRUE(codec);
    EXPECT_EQ(*codec, CodecModel::kStream);
}

TEST(EvalSetup, SummaryListsHeadlinesAndFindings) {
    EvalOutput out;
    out.headlines.push_back({"speed-up", 3.4, 3.1, 3.3, "x", ""});
    out.findings.push_back({"liwc balances", true, "ratio 1.02"});
    const std::string t = evalSummaryText(out, 1.5, "dir");
    EXPECT_EQ(t.rfind("0 runs in 1.5 s; \n", 0), 0u);
    EXPECT_NE(t.find("[holds] liwc balances: ratio 1.02\n"), std::string::npos);
    EXPECT_NE(t.find("report: dir/report.html\n"), std::string::npos);
}

}  // namespace
}  // namespace qvr
