// The sweep without processes: the conditions a seed draws, the designs of each take, the
// options checked, summary.json read, and a whole sweep through a fake runner with its ratios
// and criteria.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "qvr/experiment/sweep.h"

namespace qvr::experiment {
namespace {

SweepSpace space() {
    SweepSpace s;
    s.traces = {"trace:/a.down", "trace:/b.down@2"};
    s.scenes = {"builtin:room", "openarena:oa_dm5", "openarena:oa_dm1", "x.glb"};
    s.motions = {"m1.bvh", "m2.bvh", "m3.bvh"};
    return s;
}

TEST(SweepDraw, TheSameSeedDrawsTheSameConditionsAndAnotherSeedOthers) {
    const auto a = drawConditions(space(), 7, 20);
    const auto b = drawConditions(space(), 7, 20);
    const auto c = drawConditions(space(), 8, 20);
    ASSERT_EQ(a.size(), 20u);
    int same_as_c = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].index, static_cast<int>(i));
        EXPECT_EQ(a[i].link, b[i].link);
        EXPECT_EQ(a[i].scene, b[i].scene);
        EXPECT_EQ(a[i].motion, b[i].motion);
        EXPECT_EQ(a[i].headset_share, b[i].headset_share);
        EXPECT_EQ(a[i].gaze_seed, b[i].gaze_seed);
        same_as_c += a[i].link == c[i].link && a[i].gaze_seed == c[i].gaze_seed;
    }
    EXPECT_LT(same_as_c, 3);
    // The first conditions do not depend on how many are drawn.
    EXPECT_EQ(drawConditions(space(), 7, 3)[2].link, a[2].link);
}

TEST(SweepDraw, ConditionsCoverTheSpaceAndStayInsideIt) {
    const SweepSpace s = space();
    std::set<std::string> scenes, motions, traces;
    int constant = 0, full = 0, slow = 0, fast = 0;
    for (const SweepCondition& c : drawConditions(s, 1, 400)) {
        scenes.insert(c.scene);
        motions.insert(c.motion);
        EXPECT_GE(c.headset_share, 0.3 - 1e-9);
        EXPECT_LE(c.headset_share, 1.0);
        full += c.headset_share == 1.0;
        if (c.link.rfind("rate:", 0) == 0) {
            ++constant;
            const double mbps = std::stod(c.link.substr(5));
            EXPECT_GE(mbps, 0.995);
            EXPECT_LE(mbps, 200.5);
            slow += mbps <= 3.0;
            fast += mbps >= 50.0;
        } else {
            traces.insert(c.link);
        }
    }
    EXPECT_EQ(scenes.size(), 4u);
    EXPECT_EQ(motions.size(), 3u);
    EXPECT_EQ(traces.size(), 2u);
    EXPECT_GT(constant, 180);  // 60% of 400 on average
    EXPECT_LT(constant, 300);
    EXPECT_GT(full, 60);  // a quarter at the whole core
    // Log-spaced: as many below 3 Mbit/s as above 50 (ln 3 ≈ ln 200 − ln 50 + 0.3).
    EXPECT_GT(slow, constant / 8);
    EXPECT_GT(fast, constant / 8);
}

TEST(SweepPlan, EachTakeRunsItsDesignsRotatedByConditionAndTake) {
    SweepOptions o;
    o.adaptive = {"qvr", "sw", "ffr"};
    o.fixed_grid_deg = {2, 10};
    const auto grid0 = takeDesigns(o, 0, 0, "");
    EXPECT_EQ(grid0, (std::vector<std::string>{"qvr", "sw", "ffr", "fixed:2", "fixed:10"}));
    const auto grid1 = takeDesigns(o, 1, 0, "");
    EXPECT_EQ(grid1, (std::vector<std::string>{"sw", "ffr", "fixed:2", "fixed:10", "qvr"}));
    const auto rep = takeDesigns(o, 0, 1, "fixed:10");
    EXPECT_EQ(rep, (std::vector<std::string>{"sw", "ffr", "fixed:10", "qvr"}));
    // ffr as the best fixed is not run twice.
    EXPECT_EQ(takeDesigns(o, 0, 3, "ffr").size(), 3u);
}

TEST(SweepPlan, BadOptionsAreRefusedWithTheirName) {
    SweepArgs a = defaultSweepArgs();
    a.scenes = "builtin:room";
    a.motions = "default";
    a.traces = "";
    ASSERT_TRUE(sweepOptions(a)) << sweepOptions(a).error();
    const auto refused = [&](auto change, const std::string& what) {
        SweepArgs b = a;
        change(b);
        const auto o = sweepOptions(b);
        ASSERT_FALSE(o);
        EXPECT_NE(o.error().find(what), std::string::npos) << o.error();
    };
    refused([](SweepArgs& b) { b.conditions = 0; }, "--conditions");
    refused([](SweepArgs& b) { b.repeats = -1; }, "--repeats");
    refused([](SweepArgs& b) { b.share_min = 0.01; }, "--share-min");
    refused([](SweepArgs& b) { b.share_max = 1.5; }, "--share-max");
    refused([](SweepArgs& b) { b.rate_min_mbps = 300.0; }, "--rate-min");
    refused([](SweepArgs& b) { b.fixed_grid = "2,x"; }, "--fixed-grid");
    refused([](SweepArgs& b) { b.fixed_grid = "2,2"; }, "--fixed-grid");
    refused([](SweepArgs& b) { b.fixed_grid = ""; }, "--fixed-grid");
    refused([](SweepArgs& b) { b.designs = "sw,ffr"; }, "qvr");
    refused([](SweepArgs& b) { b.designs = "qvr,fixed:10"; }, "--fixed-grid");
    refused([](SweepArgs& b) { b.traces = "/nonexistent.down"; }, "--traces");
    refused([](SweepArgs& b) { b.scenes = "/nonexistent.glb"; }, "--scenes");
    refused([](SweepArgs& b) { b.motions = "/nonexistent.bvh"; }, "--motions");
    // A design the runtime does not know is left out and named, not fatal.
    SweepArgs b = a;
    b.designs = "qvr,nonesuch,sw";
    const auto o = sweepOptions(b);
    ASSERT_TRUE(o);
    EXPECT_EQ(o->adaptive, (std::vector<std::string>{"qvr", "sw"}));
    ASSERT_EQ(o->skipped_designs.size(), 1u);
    EXPECT_NE(o->skipped_designs[0].find("nonesuch"), std::string::npos);
}

TEST(SweepPlan, TracesComeFromFilesFoldersAndSpecsWithTheirMeans) {
    const std::filesystem::path dir = testing::TempDir() + "/qvr_sweep_traces";
    std::filesystem::create_directories(dir);
    {
        std::ofstream f(dir / "one.down");  // 2 packets a ms: 24 Mbit/s
        for (int ms = 1; ms <= 100; ++ms)
            f << ms << "\n" << ms << "\n";
    }
    SweepArgs a = defaultSweepArgs();
    a.scenes = "builtin:room";
    a.motions = "default";
    a.traces = dir.string() + ",trace:" + (dir / "one.down").string() + "@2";
    const auto o = sweepOptions(a);
    ASSERT_TRUE(o) << o.error();
    ASSERT_EQ(o->space.traces.size(), 2u);
    EXPECT_NEAR(*linkMeanMbps(o->space.traces[0]), 24.0, 1e-9);
    EXPECT_NEAR(*linkMeanMbps(o->space.traces[1]), 2.0, 1e-9);
    EXPECT_NEAR(*linkMeanMbps("rate:2.5"), 2.5, 1e-9);
    EXPECT_FALSE(linkMeanMbps("none"));
    std::filesystem::remove_all(dir);
}

TEST(SweepRead, ReadsTheDesignsOfASummaryInTheOrderAsked) {
    const auto summary = nlohmann::json::parse(R"({"designs": {
        "qvr": {"fps_mean": 40, "mtp_ms_p99": 50, "bytes_per_frame_mean": 9000,
                "e1_deg_mean": 12.5, "predicted": {"fps_mean": 44},
                "predicted_at_probe_speed": {"fps_mean": 36}},
        "fixed:10": {"fps_mean": 30, "mtp_ms_p99": 60, "bytes_per_frame_mean": 7000,
                     "e1_deg_mean": 10}}})");
    const auto r = readingsFromSummary(summary, {"fixed:10", "aimd", "qvr"});
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[0].design, "fixed:10");
    EXPECT_FALSE(r[0].fpsErrorPct());
    EXPECT_EQ(r[1].design, "qvr");
    EXPECT_DOUBLE_EQ(r[1].e1_deg, 12.5);
    EXPECT_NEAR(*r[1].fpsErrorPct(), 10.0, 1e-9);
    EXPECT_NEAR(*r[1].fpsErrorAtProbeSpeedPct(), -10.0, 1e-9);
    EXPECT_FALSE(r[0].fpsErrorAtProbeSpeedPct());  // no probes (a --headset-share run)
    EXPECT_TRUE(readingsFromSummary(nullptr, {"qvr"}).empty());
}

// FPS per design from a table; the prediction 5% high; MTP p99 1000 / FPS. 100 frames a run,
// `reused` of them re-warping older layers; `grid_luck` multiplies a design's grid take.
class FakeRunner final : public ConditionRunner {
public:
    std::map<std::string, double> fps;
    std::map<std::string, int> reused;
    std::map<std::string, double> grid_luck;
    std::vector<std::vector<std::string>> calls;
    ConditionRun run(const SweepCondition& c, const std::vector<std::string>& designs,
                     const std::string& tag) override {
        calls.push_back(designs);
        tags.push_back(tag);
        ConditionRun out;
        out.ok = true;
        for (const std::string& d : designs) {
            DesignReading r;
            r.design = d;
            r.fps = fps.at(d) * (c.index == 1 ? 0.5 : 1.0) * (calls.size() % 2 ? 1.0 : 1.1);
            if (tag.ends_with("_grid") && grid_luck.contains(d))
                r.fps *= grid_luck.at(d);
            r.frames = 100;
            r.frames_reused = reused.contains(d) ? reused.at(d) : 0;
            r.mtp_ms_p99 = 1000.0 / r.fps;
            r.predicted_fps = 1.05 * r.fps;
            if (c.index == 0)
                r.predicted_fps_at_probe_speed = 0.98 * r.fps;
            out.designs.push_back(r);
        }
        return out;
    }
    std::vector<std::string> tags;
};

TEST(SweepRun, RepeatsTheBestFixedAndJudgesTheRatios) {
    SweepOptions o;
    o.conditions = 2;
    o.repeats = 2;
    o.adaptive = {"qvr", "sw", "ffr", "aimd"};
    o.fixed_grid_deg = {2, 10, 20};
    o.space.scenes = {"builtin:room"};
    o.space.traces = {"trace:/x/a.down"};
    o.space.trace_odds = 1.0;
    FakeRunner runner;
    runner.fps = {{"qvr", 38.0},     {"sw", 30.0},       {"ffr", 20.0},     {"aimd", 35.0},
                  {"fixed:2", 15.0}, {"fixed:10", 40.0}, {"fixed:20", 33.0}};
    std::FILE* null = std::fopen("/dev/null", "w");
    const SweepResult r = executeSweep(o, runner, null);
    std::fclose(null);
    ASSERT_EQ(runner.calls.size(), 6u);  // 2 conditions × (grid + 2 repeats)
    EXPECT_EQ(runner.calls[0].size(), 7u);
    EXPECT_EQ(runner.calls[1].size(), 5u);  // the adaptive four and fixed:10
    EXPECT_NE(std::find(runner.calls[1].begin(), runner.calls[1].end(), "fixed:10"),
              runner.calls[1].end());
    EXPECT_NE(runner.calls[0].front(), runner.calls[3].front());  // rotated per condition
    EXPECT_EQ(runner.tags[0], "c01_grid");
    EXPECT_EQ(runner.tags[2], "c01_r3");
    EXPECT_EQ(r.rows.size(), 2u * (7 + 5 + 5));
    ASSERT_EQ(r.verdicts.size(), 2u);
    const ConditionVerdict& v = r.verdicts[0];
    EXPECT_EQ(v.best_fixed, "fixed:10");
    EXPECT_NEAR(*v.qvr_over_best, 0.95, 1e-9);  // the same factor on both in every take
    EXPECT_NEAR(*v.qvr_over_ffr, 1.9, 1e-9);
    EXPECT_NEAR(*v.qvr_over_aimd, 38.0 / 35.0, 1e-9);
    EXPECT_NEAR(*v.mtp_p99_over_best, 40.0 / 38.0, 1e-9);
    ASSERT_FALSE(v.spread_pct.empty());
    EXPECT_NEAR(v.spread_pct[0].second, 10.0, 1e-6);  // 1.0 and 1.1 around a median of 1.0
    std::map<std::string, bool> pass;
    for (const SweepCriterion& c : sweepCriteria(r))
        pass[c.name] = c.pass;
    EXPECT_TRUE(pass.at("qvr >= 0.90x best fixed on all"));
    EXPECT_TRUE(pass.at("qvr >= ffr on all"));
    EXPECT_TRUE(pass.at("qvr ahead of aimd on average"));
    EXPECT_TRUE(pass.at("qvr MTP p99 <= 1.10x best fixed's"));
    EXPECT_TRUE(pass.at("model FPS error mean <= 10%"));
    std::map<std::string, std::string> detail;
    for (const SweepCriterion& c : sweepCriteria(r))
        detail[c.name] = c.detail;
    // 17 runs a condition; the first condition's carry the probes' prediction, 2% low.
    EXPECT_EQ(detail.at("model FPS error mean <= 10%"),
              "5.0% over 34 runs; at the probes' speed 2.0% mean, 2.0% worst over the 17 runs "
              "with probes");
    EXPECT_FALSE(pass.at("at least 16 conditions"));
    const std::string md = sweepMarkdown(o, r);
    EXPECT_NE(md.find("PASS qvr >= ffr on all"), std::string::npos);
    EXPECT_NE(md.find("| 1 | builtin:room | trace:a.down |"), std::string::npos) << md;
    EXPECT_NE(sweepCsv(r).find("1,builtin:room,"), std::string::npos);
    EXPECT_EQ(sweepJson(o, r)["runs"].size(), r.rows.size());
}

TEST(SweepRun, FailsTheCriteriaWhereQvrFallsBehind) {
    SweepOptions o;
    o.conditions = 1;
    o.repeats = 1;
    o.adaptive = {"qvr", "ffr"};
    o.fixed_grid_deg = {10};
    FakeRunner runner;
    runner.fps = {{"qvr", 30.0}, {"ffr", 32.0}, {"fixed:10", 40.0}};
    std::FILE* null = std::fopen("/dev/null", "w");
    const SweepResult r = executeSweep(o, runner, null);
    std::fclose(null);
    std::map<std::string, SweepCriterion> by;
    for (const SweepCriterion& c : sweepCriteria(r))
        by[c.name] = c;
    EXPECT_FALSE(by.at("qvr >= 0.95x best fixed on >= 90% of conditions").pass);
    EXPECT_FALSE(by.at("qvr >= 0.90x best fixed on all").pass);
    EXPECT_FALSE(by.at("qvr >= ffr on all").pass);
    EXPECT_FALSE(by.at("qvr MTP p99 <= 1.10x best fixed's").pass);
    EXPECT_FALSE(by.at("qvr ahead of aimd on average").pass);
    EXPECT_EQ(by.at("qvr ahead of aimd on average").detail, "not measured (no aimd runs)");
}

// The slow-link criterion is judged on the slow links alone: a fast link where qvr trails does
// not fail it, and its count is of slow conditions.
TEST(SweepRun, JudgesTheSlowLinkCriterionOnSlowLinksOnly) {
    const auto slowCriterion = [](double rate_mbps, double qvr_fps) {
        SweepOptions o;
        o.conditions = 1;
        o.repeats = 1;
        o.adaptive = {"qvr", "ffr"};
        o.fixed_grid_deg = {10};
        o.space.rate_min_mbps = o.space.rate_max_mbps = rate_mbps;
        o.space.traces.clear();
        FakeRunner runner;
        runner.fps = {{"qvr", qvr_fps}, {"ffr", 20.0}, {"fixed:10", 40.0}};
        std::FILE* null = std::fopen("/dev/null", "w");
        const SweepResult r = executeSweep(o, runner, null);
        std::fclose(null);
        for (const SweepCriterion& c : sweepCriteria(r))
            if (c.name.rfind("links <=", 0) == 0)
                return c;
        return SweepCriterion{};
    };
    const SweepCriterion fast_behind = slowCriterion(100.0, 30.0);
    EXPECT_FALSE(fast_behind.pass);
    EXPECT_NE(fast_behind.detail.find("not measured"), std::string::npos) << fast_behind.detail;
    const SweepCriterion slow_behind = slowCriterion(2.0, 30.0);
    EXPECT_FALSE(slow_behind.pass);
    EXPECT_NE(slow_behind.detail.find("0/1 conditions"), std::string::npos) << slow_behind.detail;
    const SweepCriterion slow_near = slowCriterion(2.0, 39.0);
    EXPECT_TRUE(slow_near.pass) << slow_near.detail;
}

SweepResult sweepOf(FakeRunner& runner, int repeats) {
    SweepOptions o;
    o.conditions = 1;
    o.repeats = repeats;
    o.adaptive = {"qvr", "ffr"};
    o.fixed_grid_deg = {2, 10};
    std::FILE* null = std::fopen("/dev/null", "w");
    SweepResult r = executeSweep(o, runner, null);
    std::fclose(null);
    return r;
}

// Two fixed designs at the same rate (the display's vsyncs quantise it): the lower MTP p99 is the
// best fixed e1, in whichever order they ran.
TEST(SweepRun, BreaksATieForTheBestFixedByMtpWhateverTheOrder) {
    for (bool reversed : {false, true}) {
        SweepResult r;
        r.conditions.resize(1);
        std::vector<DesignReading> grid(2);
        grid[0].design = "fixed:8";
        grid[0].fps = 33.375;
        grid[0].mtp_ms_p99 = 80.0;
        grid[1].design = "fixed:12";
        grid[1].fps = 33.375;
        grid[1].mtp_ms_p99 = 70.0;
        if (reversed)
            std::swap(grid[0], grid[1]);
        for (const DesignReading& d : grid)
            r.rows.push_back({0, 0, d});
        SweepOptions o;
        const auto v = conditionVerdicts(o, r);
        ASSERT_EQ(v.size(), 1u);
        EXPECT_EQ(v[0].best_fixed, "fixed:12") << (reversed ? "reversed" : "in order");
    }
}

// A design whose frames re-warp an older periphery keeps its frame rate; the sweep judges the
// frames shown with their own layers, so it neither wins the grid nor sets the bar.
TEST(SweepRun, JudgesTheFramesShownWithTheirOwnLayers) {
    FakeRunner runner;
    runner.fps = {{"qvr", 30.0}, {"ffr", 20.0}, {"fixed:2", 55.0}, {"fixed:10", 32.0}};
    runner.reused = {{"fixed:2", 100}, {"qvr", 10}};
    const SweepResult r = sweepOf(runner, 1);
    ASSERT_EQ(r.verdicts.size(), 1u);
    const ConditionVerdict& v = r.verdicts[0];
    EXPECT_EQ(v.best_fixed, "fixed:10");
    EXPECT_NEAR(*v.qvr_over_best, 27.0 / 32.0, 1e-9);
    EXPECT_NEAR(*v.qvr_over_best_all_frames, 30.0 / 32.0, 1e-9);
    EXPECT_NEAR(*v.qvr_over_ffr, 27.0 / 20.0, 1e-9);
    // ffr showing none of its own frames: qvr, which did, is ahead of it.
    FakeRunner stale = runner;
    stale.calls.clear();
    stale.tags.clear();
    stale.reused["ffr"] = 100;
    EXPECT_TRUE(std::isinf(*sweepOf(stale, 1).verdicts[0].qvr_over_ffr));
    DesignReading d;
    d.fps = 40.0;
    d.frames = 80;
    d.frames_reused = 20;
    EXPECT_DOUBLE_EQ(d.freshFps(), 30.0);
    d.frames = 0;  // no counts (an older summary): every frame its own
    EXPECT_DOUBLE_EQ(d.freshFps(), 40.0);
    const std::string csv = sweepCsv(r);
    EXPECT_NE(csv.find(",fixed:2,55.00,100,100,0.00,"), std::string::npos) << csv;
}

// The best fixed e1 is the grid take's highest of several noisy values: judged on that value it
// is favoured, so it is judged on the repeats, qvr on the same takes.
TEST(SweepRun, ChoosesTheBestFixedOnTheGridAndJudgesItOnTheRepeats) {
    FakeRunner runner;
    runner.fps = {{"qvr", 38.0}, {"ffr", 20.0}, {"fixed:2", 15.0}, {"fixed:10", 40.0}};
    runner.grid_luck = {{"fixed:10", 1.2}};
    const SweepResult repeated = sweepOf(runner, 2);
    ASSERT_EQ(repeated.verdicts.size(), 1u);
    EXPECT_EQ(repeated.verdicts[0].best_fixed, "fixed:10");
    EXPECT_NEAR(repeated.verdicts[0].best_fixed_fps, 48.0, 1e-9);
    EXPECT_NEAR(*repeated.verdicts[0].qvr_over_best, 0.95, 1e-9);  // the repeats alone
    FakeRunner once = runner;
    once.calls.clear();
    once.tags.clear();
    const SweepResult grid_only = sweepOf(once, 0);  // no repeat: the grid's take is all there is
    EXPECT_NEAR(*grid_only.verdicts[0].qvr_over_best, 38.0 / 48.0, 1e-9);
}

void writeSummary(const std::filesystem::path& dir, const std::string& text) {
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "summary.json") << text;
}

// `qvr sweep --from DIR` reads each take's summary.json; a missing or unreadable one is a failed
// run with its path, never a silent zero.
TEST(SweepStored, JudgesAnEarlierSweepsRunsAndNamesWhatIsMissing) {
    const auto dir = std::filesystem::temp_directory_path() / "qvr_sweep_stored_test";
    std::filesystem::remove_all(dir);
    writeSummary(dir / "c01_grid", R"({"designs": {
        "qvr": {"fps_mean": 30, "frames": 100, "frames_reused": 0},
        "ffr": {"fps_mean": 20, "frames": 100, "frames_reused": 0},
        "fixed:2": {"fps_mean": 50, "frames": 100, "frames_reused": 90},
        "fixed:10": {"fps_mean": 32, "frames": 100, "frames_reused": 0}}})");
    writeSummary(dir / "c01_r2", R"({"designs": {
        "qvr": {"fps_mean": 31, "frames": 100, "frames_reused": 0},
        "fixed:2": {"fps_mean": 51, "frames": 100, "frames_reused": 90}}})");
    writeSummary(dir / "c01_r3", "{not json");
    SweepOptions o;
    o.conditions = 1;
    o.repeats = 3;
    o.adaptive = {"qvr", "ffr"};
    o.fixed_grid_deg = {2, 10};
    StoredConditionRunner stored(dir.string());
    std::FILE* null = std::fopen("/dev/null", "w");
    const SweepResult r = executeSweep(o, stored, null);
    std::fclose(null);
    EXPECT_EQ(r.failed_runs, 2);  // c01_r3 unreadable, c01_r4 missing
    ASSERT_EQ(r.verdicts.size(), 1u);
    EXPECT_EQ(r.verdicts[0].best_fixed, "fixed:10");
    // fixed:10 has no repeat: qvr and it are judged on the grid's take, the one both ran.
    EXPECT_NEAR(*r.verdicts[0].qvr_over_best, 30.0 / 32.0, 1e-9);
    EXPECT_EQ(r.rows.size(), 6u);
    const ConditionRun missing = stored.run({}, {}, "c09_grid");
    EXPECT_FALSE(missing.ok);
    EXPECT_NE(missing.note.find("c09_grid"), std::string::npos) << missing.note;
    SweepArgs a = defaultSweepArgs();
    a.from = (dir / "nowhere").string();
    const auto refused = sweepOptions(a);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().find("--from"), std::string::npos) << refused.error();
    std::filesystem::remove_all(dir);
}

// Records the command lines it is given; every run "fails" (no summary), which is all the
// command's test needs.
class RecordingChildren final : public ChildRunner {
public:
    ChildOutcome run(const ChildCommand& command) override {
        lines.push_back(command.line);
        return {};
    }
    int stopSignal() const override { return 0; }
    std::vector<std::string> lines;
};

// A scene's first run measures its calibration afresh (a cached one from another hour of a
// drifting host biased a whole scene's predictions: oa_dm1's ffr +40%, −2…+8% once measured
// again); its later runs, --hardware and --cached-calibration do not.
TEST(SweepProcessRunner, RecalibratesEachSceneAtItsFirstRunOnly) {
    SweepOptions o;
    o.executable = "qvr";
    o.out = "/tmp/qvr-sweep-test";
    SweepCondition room{0, "wifi", 1.0, "builtin:room", "m1.bvh", 1};
    SweepCondition dm5{1, "wifi", 0.5, "openarena:oa_dm5", "m2.bvh", 2};
    const auto recalibrating = [&](const SweepOptions& options) {
        RecordingChildren children;
        ProcessConditionRunner runner(options, children);
        for (const SweepCondition& c : {room, dm5, room, dm5, room})
            runner.run(c, {"qvr"}, fmt::format("c{}", c.index));
        std::vector<bool> out;
        for (const std::string& line : children.lines)
            out.push_back(line.find(" --recalibrate") != std::string::npos);
        return out;
    };
    EXPECT_EQ(recalibrating(o), (std::vector<bool>{true, true, false, false, false}));
    SweepOptions cached = o;
    cached.cached_calibration = true;
    EXPECT_EQ(recalibrating(cached), std::vector<bool>(5, false));
    SweepOptions given = o;
    given.hardware = "/tmp/cal.toml";
    EXPECT_EQ(recalibrating(given), std::vector<bool>(5, false));
}

}  // namespace
}  // namespace qvr::experiment
