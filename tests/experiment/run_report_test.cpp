// `qvr run`'s report from a hand-made result: summary.json's keys and values, the best fixed
// design, the headline ratios, what limits a design, the validation table, the speed over a run.
#include "qvr/experiment/run_report.h"

#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include <cmath>

namespace qvr::experiment {
namespace {

std::set<std::string> keysOf(const nlohmann::json& j) {
    std::set<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it)
        keys.insert(it.key());
    return keys;
}

DesignResult design(Design kind, double e1, double fps, double bytes) {
    DesignResult d;
    d.spec.design = kind;
    d.spec.fixed_e1_deg = e1;
    d.name = d.spec.label();
    d.summary.design = d.name;
    d.summary.fps_mean = fps;
    d.summary.bytes_per_frame_mean = bytes;
    d.summary.e1_deg_mean = e1;
    d.summary.mtp_ms_p99 = 40.0;
    d.measured = measuredMetrics(d.summary, std::nullopt);
    return d;
}

// A design measured, predicted by both models and at the probes' speed.
DesignResult predictedQvr() {
    DesignResult d = design(Design::Qvr, 0.0, 50.0, 2000.0);
    d.summary.e1_deg_mean = 10.0;
    d.summary.headset_busy_ms_mean = 15.0;
    d.summary.headset_busy_frames = 100;
    d.summary.frames = 140;
    d.stats.streams_decoded = 7;
    d.stats.key_frame_requests = 2;
    d.measured = measuredMetrics(d.summary, 8.0);
    d.speed_before = SpeedSample{10.0, 20.0};
    d.prediction.calibrated =
        RuntimePrediction{{55.0, 30.0, 45.0, 2200.0, 11.0, 16.5, 8.0}, 12.0, 3};
    d.prediction.speed = SideFactors{1.1, 1.2};
    d.prediction.at_probe_speed = DesignMetrics{50.0, 31.0, 46.0, 2200.0, 10.5, 18.0, 9.0};
    d.prediction.paper_hardware =
        DesignMetrics{70.0, 20.0, 25.0, 1800.0, 9.0, std::nullopt, std::nullopt};
    d.error = predictionError(d.prediction.calibrated->metrics, d.measured);
    d.error_at_probe_speed = predictionError(*d.prediction.at_probe_speed, d.measured);
    return d;
}

TEST(DesignJson, MeasuredPredictedErrorsAndSpeed) {
    const nlohmann::json j = designJson(predictedQvr());
    EXPECT_EQ(keysOf(j), (std::set<std::string>{"fps_mean",
                                                "mtp_ms_mean",
                                                "mtp_ms_p99",
                                                "bytes_per_frame_mean",
                                                "e1_deg_mean",
                                                "frames_displayed",
                                                "frames_reused",
                                                "frames_new_layers",
                                                "frames",
                                                "frames_fallback_local",
                                                "t_local_ms_mean",
                                                "t_remote_ms_mean",
                                                "uca_ms_mean",
                                                "wall_s",
                                                "warmup_frames",
                                                "startup_mtp_ms_max",
                                                "startup_unfinished",
                                                "streams_decoded",
                                                "streams_lost",
                                                "decode_failures",
                                                "late_frames",
                                                "requests_withheld",
                                                "key_frame_requests",
                                                "fec_recoveries",
                                                "fec_packets_recovered",
                                                "nacks_sent",
                                                "packets_recovered",
                                                "media_forged",
                                                "media_replayed",
                                                "media_drops",
                                                "client_core",
                                                "headset_busy_ms_mean",
                                                "server_busy_ms_mean",
                                                "predicted",
                                                "prediction_error_pct",
                                                "prediction_error_abs",
                                                "predicted_paper_hardware",
                                                "predicted_at_probe_speed",
                                                "prediction_error_pct_at_probe_speed",
                                                "prediction_error_abs_at_probe_speed",
                                                "speed"}));
    EXPECT_EQ(j["frames"], 140);
    EXPECT_EQ(j["streams_decoded"], 7);
    EXPECT_EQ(j["key_frame_requests"], 2);
    EXPECT_EQ(j["headset_busy_ms_mean"], 15.0);
    EXPECT_EQ(j["server_busy_ms_mean"], 8.0);
    EXPECT_EQ(j["predicted"], (nlohmann::json{{"fps_mean", 55.0},
                                              {"mtp_ms_mean", 30.0},
                                              {"mtp_ms_p99", 45.0},
                                              {"bytes_per_frame_mean", 2200.0},
                                              {"e1_deg_mean", 11.0},
                                              {"headset_busy_ms_mean", 16.5},
                                              {"server_busy_ms_mean", 8.0},
                                              {"t_remote_ms_mean", 12.0},
                                              {"frames_reused", 3}}));
    EXPECT_NEAR(j["prediction_error_pct"]["fps_mean"].get<double>(), 10.0, 1e-9);
    EXPECT_NEAR(j["prediction_error_pct"]["headset_busy_ms_mean"].get<double>(), 10.0, 1e-9);
    EXPECT_TRUE(j["prediction_error_pct"]["mtp_ms_mean"].is_null());  // measured 0
    EXPECT_EQ(keysOf(j["prediction_error_pct"]).size(), 7u);
    EXPECT_EQ(j["prediction_error_abs"], (nlohmann::json{{"e1_deg_mean", 1.0}}));
    EXPECT_EQ(j["prediction_error_abs_at_probe_speed"], (nlohmann::json{{"e1_deg_mean", 0.5}}));
    EXPECT_EQ(keysOf(j["predicted_paper_hardware"]),
              (std::set<std::string>{"fps_mean", "mtp_ms_mean", "mtp_ms_p99",
                                     "bytes_per_frame_mean", "e1_deg_mean"}));
    EXPECT_EQ(keysOf(j["predicted_at_probe_speed"]).size(), 7u);
    EXPECT_EQ(j["speed"],
              (nlohmann::json{{"before", {{"headset_frame_ms", 10.0}, {"server_frame_ms", 20.0}}},
                              {"after", nullptr},
                              {"headset_factor", 1.1},
                              {"server_factor", 1.2}}));
}

TEST(DesignJson, AnUnpredictedDesignHasNullsAndNoPrediction) {
    const nlohmann::json j = designJson(design(Design::Local, 0.0, 30.0, 0.0));
    EXPECT_TRUE(j["headset_busy_ms_mean"].is_null());
    EXPECT_TRUE(j["server_busy_ms_mean"].is_null());
    EXPECT_FALSE(j.contains("predicted"));
    EXPECT_FALSE(j.contains("prediction_error_pct"));
    EXPECT_FALSE(j.contains("predicted_paper_hardware"));
    EXPECT_EQ(j["speed"], (nlohmann::json{{"before", nullptr}, {"after", nullptr}}));
}

TEST(BestFixed, TheFastestFixedDesignAndTheAdaptiveOnesOverIt) {
    const std::vector<DesignResult> designs = {
        design(Design::Local, 0.0, 90.0, 0.0),  design(Design::Ffr, 5.0, 40.0, 0.0),
        design(Design::Fixed, 10.0, 50.0, 0.0), design(Design::Fixed, 20.0, 45.0, 0.0),
        design(Design::Qvr, 0.0, 60.0, 0.0),    design(Design::Sw, 0.0, 25.0, 0.0)};
    const auto bf = bestFixed(designs);
    ASSERT_TRUE(bf);
    EXPECT_EQ(bf->design, "fixed:10");
    EXPECT_DOUBLE_EQ(bf->e1_deg, 10.0);
    EXPECT_DOUBLE_EQ(bf->fps_mean, 50.0);
    ASSERT_EQ(bf->fps_over_best.size(), 2u);
    EXPECT_EQ(bf->fps_over_best[0].first, "qvr");
    EXPECT_DOUBLE_EQ(bf->fps_over_best[0].second, 1.2);
    EXPECT_EQ(bf->fps_over_best[1].first, "sw");
    EXPECT_DOUBLE_EQ(bf->fps_over_best[1].second, 0.5);
    EXPECT_FALSE(bestFixed({design(Design::Qvr, 0.0, 60.0, 0.0)}));
}

// As qvr sweep judges: a fixed design whose layers stopped coming re-warped an old periphery at
// full rate (seed 2027 c13's fixed:2 "ran" at 55.7 FPS with 100 of 100 frames reused); the best
// fixed e1 is the one showing the most frames with their own layers, a tie going to the lower
// MTP p99, and a ratio over a fixed design with none of its own is infinite ("inf" in JSON).
TEST(BestFixed, ChoosesByFramesWithTheirOwnLayersAndBreaksATieByMtp) {
    std::vector<DesignResult> designs = {
        design(Design::Fixed, 2.0, 55.7, 0.0), design(Design::Fixed, 8.0, 30.0, 0.0),
        design(Design::Fixed, 12.0, 30.0, 0.0), design(Design::Qvr, 0.0, 33.0, 0.0)};
    designs[0].summary.frames = 100;
    designs[0].summary.frames_reused = 100;
    designs[1].summary.mtp_ms_p99 = 90.0;
    designs[2].summary.mtp_ms_p99 = 80.0;
    designs[3].summary.frames = 100;
    designs[3].summary.frames_reused = 10;  // 29.7 FPS with its own layers
    auto bf = bestFixed(designs);
    ASSERT_TRUE(bf);
    EXPECT_EQ(bf->design, "fixed:12");
    EXPECT_DOUBLE_EQ(bf->fps_mean, 30.0);
    ASSERT_EQ(bf->fps_over_best.size(), 1u);
    EXPECT_DOUBLE_EQ(bf->fps_over_best[0].second, 0.99);
    // The same runs in the other order: the same choice.
    std::swap(designs[1], designs[2]);
    EXPECT_EQ(bestFixed(designs)->design, "fixed:12");
    // Only the stale one: qvr over it is infinite.
    bf = bestFixed({designs[0], designs[3]});
    ASSERT_TRUE(bf);
    EXPECT_TRUE(std::isinf(bf->fps_over_best[0].second));
    EXPECT_EQ(bestFixedJson(*bf)["qvr_fps_over_best_fixed"], "inf");
}

// A design whose layers came in its start-up and none newer after: qvr run exits 1 for it (never
// for one that showed late frames' layers, nor for one that asked for none).
TEST(ShowedNoNewLayers, OnlyADesignThatAskedAndShowedNothingNew) {
    runtime::DesignSummary s;
    s.frames = 100;
    s.frames_reused = 100;
    s.frames_remote_requested = 100;
    s.frames_new_layers = 0;
    EXPECT_TRUE(showedNoNewLayers(s));
    s.frames_new_layers = 40;  // remote on a slow server: every frame late, each new
    EXPECT_FALSE(showedNoNewLayers(s));
    s.frames_new_layers = 0;
    s.frames_remote_requested = 0;  // local
    EXPECT_FALSE(showedNoNewLayers(s));
    s.frames_remote_requested = 100;
    s.startup_unfinished = true;  // never showed one: its own exit message
    EXPECT_FALSE(showedNoNewLayers(s));
}

// A design whose layers stop arriving keeps its frame rate by re-warping an old periphery: the
// console says so rather than let the FPS stand alone.
TEST(ReusedPeripheryWarning, NamesADesignShowingMostlyOldLayers) {
    runtime::DesignSummary s;
    s.design = "fixed:2";
    s.frames = 100;
    s.fps_mean = 55.0;
    s.frames_reused = 50;
    EXPECT_FALSE(reusedPeripheryWarning(s));
    s.frames_reused = 90;
    const auto w = reusedPeripheryWarning(s);
    ASSERT_TRUE(w);
    EXPECT_NE(w->find("fixed:2: 90 of 100 frames"), std::string::npos) << *w;
    EXPECT_NE(w->find("5.5 FPS had their own"), std::string::npos) << *w;
    EXPECT_FALSE(reusedPeripheryWarning(runtime::DesignSummary{}));
}

TEST(HeadlineRatios, MeasuredAndPaperModel) {
    DesignResult local = design(Design::Local, 0.0, 20.0, 0.0);
    DesignResult remote = design(Design::Remote, 0.0, 30.0, 10000.0);
    DesignResult qvr = design(Design::Qvr, 0.0, 50.0, 2500.0);
    local.prediction.paper_hardware = DesignMetrics{10.0, 0, 0, 0.0, 0, std::nullopt, std::nullopt};
    qvr.prediction.paper_hardware =
        DesignMetrics{40.0, 0, 0, 1000.0, 0, std::nullopt, std::nullopt};
    HeadlineRatios r = headlineRatios({local, remote, qvr});
    EXPECT_DOUBLE_EQ(*r.qvr_fps_over_local, 2.5);
    EXPECT_DOUBLE_EQ(*r.qvr_bytes_saved_vs_remote, 0.75);
    EXPECT_DOUBLE_EQ(*r.sim_qvr_fps_over_local, 4.0);
    EXPECT_FALSE(r.sim_qvr_bytes_saved_vs_remote);  // no paper prediction for remote
    const nlohmann::json j = ratiosJson(r);
    EXPECT_EQ(keysOf(j),
              (std::set<std::string>{"qvr_fps_over_local", "qvr_bytes_saved_vs_remote",
                                     "paper_qvr_fps_over_local", "paper_qvr_bytes_saved_vs_remote",
                                     "sim_qvr_fps_over_local"}));
    EXPECT_EQ(j["paper_qvr_fps_over_local"], 3.4);
    EXPECT_EQ(j["paper_qvr_bytes_saved_vs_remote"], 0.85);
    EXPECT_EQ(keysOf(ratiosJson(headlineRatios({qvr}))).size(), 2u);
}

TEST(DesignLimits, TheSlowerSideAndTheHeadsetsBusiestStage) {
    std::vector<runtime::FrameTelemetry> frames(2);
    for (auto& t : frames) {
        t.pose_ns = 0;
        t.decision_ns = 1'000'000;  // 1 ms
        t.t_local_ms = 8.0;
        t.uca_ms = 3.0;
        t.headset_busy_ms = 12.0;
    }
    frames[1].remote_requested = true;
    frames[1].t_remote_ms = 10.0;
    auto l = designLimits(frames);
    ASSERT_TRUE(l);
    EXPECT_DOUBLE_EQ(l->decision_ms, 1.0);
    EXPECT_DOUBLE_EQ(l->t_remote_ms, 10.0);  // over the frames that asked
    EXPECT_EQ(l->limit, "headset: busiest stage the local render");
    frames[1].t_remote_ms = 20.0;
    l = designLimits(frames);
    EXPECT_EQ(l->limit.rfind("server:", 0), 0u) << l->limit;
    EXPECT_FALSE(designLimits({}));
}

RunOutcome handMadeOutcome() {
    RunOutcome o;
    o.command = "qvr run --frames 20";
    o.date = "2000-01-01 00:00 UTC";
    o.machine = "2 × test CPU";
    o.scene = "room";
    o.profile.name = "small";
    o.profile.width_px = 320;
    o.profile.height_px = 360;
    o.profile.refresh_hz = 90.0;
    o.net = "wifi";
    o.frames_per_design = 20;
    o.designs_requested = 2;
    o.designs = {design(Design::Ffr, 5.0, 40.0, 500.0), predictedQvr()};
    o.designs[0].quality = DesignQuality{};
    o.designs[0].quality->frames = 1;
    o.designs[0].quality->counted = {1, 0, 0, 0, 1};
    o.designs[0].quality->psnr_db = {40.0, 0, 0, 0, 30.0};
    o.designs[0].quality->psnr_by_ecc[2.5] = {80.0, 2};
    o.calibration.source = "file";
    o.calibration.path = "cal.toml";
    o.calibration.note = "calibration from cal.toml";
    o.server_stats = {{"layers_rendered", 4}, {"encode_ms_total", 10.0}};
    o.server_status = 0;
    return o;
}

TEST(SummaryJson, EveryKeyFromTheTypedResult) {
    const nlohmann::json j = summaryJson(handMadeOutcome());
    EXPECT_EQ(keysOf(j), (std::set<std::string>{"command",
                                                "date",
                                                "machine",
                                                "scene",
                                                "profile",
                                                "net",
                                                "frames_per_design",
                                                "interrupted",
                                                "designs_requested",
                                                "designs_run",
                                                "pinning",
                                                "run_seconds",
                                                "headset_share",
                                                "designs",
                                                "best_fixed",
                                                "ratios",
                                                "sim_prediction",
                                                "calibration",
                                                "server",
                                                "trace",
                                                "quality"}));
    EXPECT_EQ(j["profile"],
              (nlohmann::json{
                  {"name", "small"}, {"width_px", 320}, {"height_px", 360}, {"refresh_hz", 90.0}}));
    EXPECT_EQ(keysOf(j["designs"]), (std::set<std::string>{"ffr", "qvr"}));
    EXPECT_EQ(j["designs_run"], 2);
    EXPECT_EQ(keysOf(j["sim_prediction"]), (std::set<std::string>{"qvr"}));
    EXPECT_EQ(j["best_fixed"]["design"], "ffr");
    EXPECT_DOUBLE_EQ(j["best_fixed"]["qvr_fps_over_best_fixed"].get<double>(), 50.0 / 40.0);
    EXPECT_EQ(j["server"], (nlohmann::json{{"layers_rendered", 4},
                                           {"encode_ms_total", 10.0},
                                           {"exit_status", 0},
                                           {"encode_ms_per_layer", 2.5}}));
    EXPECT_EQ(j["trace"], nlohmann::json::object());
    EXPECT_EQ(j["quality"], (nlohmann::json{{"ffr",
                                             {{"frames_sampled", 1},
                                              {"seconds", 0.0},
                                              {"fovea", {{"psnr_db", 40.0}, {"ssim", 0.0}}},
                                              {"all", {{"psnr_db", 30.0}, {"ssim", 0.0}}},
                                              {"psnr_db_by_eccentricity_deg", {{2.5, 40.0}}}}}}));
    EXPECT_EQ(keysOf(j["calibration"]),
              (std::set<std::string>{"source", "path", "seconds", "note", "bits_frames_own",
                                     "workload", "pipeline_depth", "speed_reference"}));
    EXPECT_TRUE(j["calibration"]["speed_reference"]["run_over_reference"].is_null());
}

TEST(SummaryJson, NotesAndOptionalPartsWhenPresent) {
    RunOutcome o = handMadeOutcome();
    o.interrupted = true;
    o.interrupted_note = "interrupted between designs";
    o.sim_note = "a note";
    o.quality_note = "no reference renderer";
    o.headset_throttling = runtime::CpuShareGroup::Throttling{10, 2, 3.5};
    o.cgroup = "/sys/fs/cgroup/x";
    o.video.info = VideoFileInfo{"mov", "h264", "High", 480, 270, 90.0, 20, 1};
    o.speed.over_reference = {1.05, 0.95};
    const nlohmann::json j = summaryJson(o);
    EXPECT_EQ(j["interrupted_note"], "interrupted between designs");
    EXPECT_EQ(j["sim_note"], "a note");
    EXPECT_EQ(j["quality"]["note"], "no reference renderer");
    EXPECT_EQ(j["headset_throttling"]["throttled_periods"], 2);
    EXPECT_EQ(j["video"]["frames"], 20);
    EXPECT_EQ(j["video"]["path"], "qvr_display.mp4");
    EXPECT_EQ(j["calibration"]["speed_reference"]["run_over_reference"]["server"], 0.95);
}

TEST(ValidationHtml, PredictedDesignsByNameWithTheirErrors) {
    RunOutcome o = handMadeOutcome();
    const std::string h = validationHtml(o);
    EXPECT_NE(h.find("<td rowspan='7'>qvr<br><small>speed ×1.100 headset, ×1.200 server</small>"),
              std::string::npos)
        << h;
    EXPECT_EQ(h.find(">ffr<"), std::string::npos);  // not predicted: no rows
    // FPS: measured 50, calibrated 55 (+10%), at the probes' speed 50 (+0%), paper 70.
    EXPECT_NE(h.find("<td style='text-align:left'>FPS</td><td>50.0</td><td>55.0</td>"
                     "<td>+10.0%</td><td>50.0</td><td>+0.0%</td><td>70.0</td>"),
              std::string::npos)
        << h;
    EXPECT_NE(h.find("<td>+1.0°</td>"), std::string::npos);
    // The paper model has no headset busy time.
    EXPECT_NE(h.find("headset busy ms/frame</td><td>15.0</td><td>16.5</td><td>+10.0%</td>"
                     "<td>18.0</td><td>+20.0%</td><td>—</td>"),
              std::string::npos)
        << h;
}

RunOutcome twoHeadsets() {
    RunOutcome o = handMadeOutcome();
    o.headsets = 2;
    o.identical_workloads = true;
    for (const DesignResult& d : o.designs) {
        std::vector<HeadsetOutcome> hs(2);
        for (int k = 0; k < 2; ++k) {
            hs[size_t(k)].index = k;
            hs[size_t(k)].workload = {"default", "model", 1};
            hs[size_t(k)].summary = d.summary;
            hs[size_t(k)].summary.fps_mean = 30.0 + 10.0 * k;
        }
        o.headsets_by_design.push_back(aggregateHeadsets(d.name, hs, ServerShare{4, 20.0}));
    }
    return o;
}

TEST(SummaryJson, SeveralHeadsetsAddTheirListFairnessAndServerTime) {
    const nlohmann::json one = summaryJson(handMadeOutcome());
    for (const char* key : {"headsets", "jain_fairness_fps", "server_ms_per_headset_frame",
                            "headsets_by_design", "headsets_requested"})
        EXPECT_FALSE(one.contains(key)) << key;
    const nlohmann::json j = summaryJson(twoHeadsets());
    EXPECT_EQ(j["headsets_design"], "qvr");
    ASSERT_EQ(j["headsets"].size(), 2u);
    EXPECT_DOUBLE_EQ(j["headsets"][1]["fps_mean"].get<double>(), 40.0);
    EXPECT_NEAR(j["jain_fairness_fps"].get<double>(), 4900.0 / (2.0 * 2500.0), 1e-12);
    EXPECT_DOUBLE_EQ(j["server_ms_per_headset_frame"].get<double>(), 5.0);
    EXPECT_EQ(keysOf(j["headsets_by_design"]), (std::set<std::string>{"ffr", "qvr"}));
    EXPECT_EQ(j["headsets_requested"], 2);
    EXPECT_EQ(j["identical_workloads"], true);
}

TEST(WriteRunReport, SeveralHeadsetsHaveTheirTable) {
    const auto dir = std::filesystem::temp_directory_path() / "qvr_run_report_headsets_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    writeRunReport(twoHeadsets(), dir);
    std::ifstream r(dir / "report.html");
    const std::string html((std::istreambuf_iterator<char>(r)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("2 headsets on one server"), std::string::npos);
    EXPECT_NE(html.find("server ms per headset-frame"), std::string::npos);
    EXPECT_NE(html.find("0.980"), std::string::npos);  // Jain's index of 30 and 40 FPS
    std::filesystem::remove_all(dir);
}

TEST(WriteRunReport, SummaryAndReportFromTheResult) {
    const auto dir = std::filesystem::temp_directory_path() / "qvr_run_report_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const RunOutcome o = handMadeOutcome();
    writeRunReport(o, dir);
    std::ifstream f(dir / "summary.json");
    EXPECT_EQ(nlohmann::json::parse(f), summaryJson(o));
    std::ifstream r(dir / "report.html");
    const std::string html((std::istreambuf_iterator<char>(r)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("Best fixed fovea in hindsight among those run: ffr at 40.0 FPS"),
              std::string::npos);
    EXPECT_NE(html.find("qvr reaches 1.25x its FPS."), std::string::npos);
    EXPECT_NE(html.find("Measured against the simulator"), std::string::npos);
    EXPECT_NE(html.find("Image quality against a full-resolution render"), std::string::npos);
    std::ifstream sweep(dir / "fps_vs_e1.csv");
    std::string header, ffr;
    std::getline(sweep, header);
    std::getline(sweep, ffr);
    EXPECT_EQ(ffr, "ffr,fixed,5.000,40.000,40.000");
    std::filesystem::remove_all(dir);
}

TEST(RunSpeed, SpreadAndMeanOverTheReference) {
    RuntimeCosts costs;
    costs.speed_reference_headset_ms = 10.0;
    costs.speed_reference_server_ms = 20.0;
    std::vector<DesignRun> runs(2);
    runs[0].speed_before = SpeedSample{10.0, 20.0};
    runs[1].speed_before = SpeedSample{12.0, 20.0};
    runs[1].speed_after = SpeedSample{11.0, 20.0};
    const RunSpeed s = runSpeed(runs, costs);
    EXPECT_NEAR(s.spread_pct[0], 20.0, 1e-9);
    EXPECT_NEAR(s.spread_pct[1], 0.0, 1e-9);
    EXPECT_NEAR(s.over_reference[0], 1.1, 1e-12);
    EXPECT_NEAR(s.over_reference[1], 1.0, 1e-12);
    EXPECT_TRUE(s.unsteady);
    costs.speed_reference_headset_ms = 0.0;
    EXPECT_EQ(runSpeed(runs, costs).over_reference[0], 0.0);
    EXPECT_FALSE(runSpeed({}, costs).unsteady);
}

}  // namespace
}  // namespace qvr::experiment
