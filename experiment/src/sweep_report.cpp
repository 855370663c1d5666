// The sweep's outputs: every run's row, each condition's ratios and spread, and the claim's
// criteria judged on them, as markdown, CSV and JSON (sweep.h).
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "qvr/core/text_file.h"
#include "qvr/experiment/host.h"
#include "qvr/experiment/sweep.h"

namespace qvr::experiment {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The claim's thresholds (issue 37's "done when").
constexpr double kNearBest = 0.95, kFloorBest = 0.90, kNearBestShare = 0.90;
constexpr double kMtpOverBest = 1.10, kSlowLinkMbps = 3.0;
constexpr double kModelMeanPct = 10.0, kModelWorstPct = 25.0;
constexpr int kMinConditions = 16;

// A trace link by its file name (the folder is in sweep.json).
std::string linkLabel(const std::string& link) {
    return link.rfind("trace:", 0) == 0 ? "trace:" + fs::path(link.substr(6)).filename().string()
                                        : link;
}

std::string cell(const std::optional<double>& v, const char* spec) {
    return v ? fmt::format(fmt::runtime(spec), *v) : "—";
}

// JSON has no infinity: a ratio over a design with none of its own frames is the string "inf".
json optJson(const std::optional<double>& v) {
    if (v && std::isinf(*v))
        return "inf";
    return v ? json(*v) : json(nullptr);
}

// Conditions whose `field` is set, and how many of them satisfy `ok`.
struct Count {
    int judged = 0, met = 0;
    std::string worst;  // "c03 0.87"
    double worst_value = INFINITY;
};
template <typename Ok>
Count countVerdicts(const std::vector<ConditionVerdict>& verdicts,
                    std::optional<double> ConditionVerdict::*field, Ok ok, bool low_is_bad = true) {
    Count n;
    for (const ConditionVerdict& v : verdicts) {
        const std::optional<double>& x = v.*field;
        if (!x)
            continue;
        ++n.judged;
        n.met += ok(v, *x) ? 1 : 0;
        const double key = low_is_bad ? *x : -*x;
        if (key < n.worst_value) {
            n.worst_value = key;
            n.worst = fmt::format("worst c{:02} {:.2f}", v.condition + 1, *x);
        }
    }
    return n;
}

// Mean and worst absolute FPS error over every run that has one.
struct ErrorStats {
    double sum = 0.0, worst = 0.0;
    int n = 0;
    double mean() const { return n > 0 ? sum / n : 0.0; }
};
ErrorStats errorStats(const SweepResult& r, std::optional<double> (DesignReading::*error)() const) {
    ErrorStats s;
    for (const SweepRow& row : r.rows)
        if (const auto e = (row.reading.*error)()) {
            s.sum += std::fabs(*e);
            s.worst = std::max(s.worst, std::fabs(*e));
            ++s.n;
        }
    return s;
}

SweepCriterion allOf(std::string name, const Count& n) {
    return {std::move(name), n.judged > 0 && n.met == n.judged,
            n.judged == 0 ? "not measured"
                          : fmt::format("{}/{} conditions; {}", n.met, n.judged, n.worst)};
}

}  // namespace

std::vector<SweepCriterion> sweepCriteria(const SweepResult& r) {
    const auto& v = r.verdicts;
    std::vector<SweepCriterion> out;
    const auto near = countVerdicts(v, &ConditionVerdict::qvr_over_best,
                                    [](const auto&, double x) { return x >= kNearBest; });
    out.push_back({fmt::format("qvr >= {:.2f}x best fixed on >= {:.0f}% of conditions", kNearBest,
                               100.0 * kNearBestShare),
                   near.judged > 0 && near.met >= kNearBestShare * near.judged,
                   near.judged == 0
                       ? "not measured"
                       : fmt::format("{}/{} conditions; {}", near.met, near.judged, near.worst)});
    out.push_back(allOf(fmt::format("qvr >= {:.2f}x best fixed on all", kFloorBest),
                        countVerdicts(v, &ConditionVerdict::qvr_over_best,
                                      [](const auto&, double x) { return x >= kFloorBest; })));
    out.push_back(
        allOf("qvr >= ffr on all", countVerdicts(v, &ConditionVerdict::qvr_over_ffr,
                                                 [](const auto&, double x) { return x >= 1.0; })));
    double aimd_sum = 0.0;
    int aimd_n = 0;
    for (const ConditionVerdict& c : v)
        if (c.qvr_over_aimd) {
            aimd_sum += *c.qvr_over_aimd;
            ++aimd_n;
        }
    out.push_back({"qvr ahead of aimd on average", aimd_n > 0 && aimd_sum / aimd_n > 1.0,
                   aimd_n == 0 ? "not measured (no aimd runs)"
                               : fmt::format("mean qvr/aimd {:.2f} over {} conditions",
                                             aimd_sum / aimd_n, aimd_n)});
    out.push_back(allOf(fmt::format("qvr MTP p99 <= {:.2f}x best fixed's", kMtpOverBest),
                        countVerdicts(
                            v, &ConditionVerdict::mtp_p99_over_best,
                            [](const auto&, double x) { return x <= kMtpOverBest; }, false)));
    std::vector<ConditionVerdict> slow;  // the slow-link criterion counts slow links only
    for (const ConditionVerdict& c : v)
        if (c.link_mbps && *c.link_mbps <= kSlowLinkMbps)
            slow.push_back(c);
    out.push_back(allOf(
        fmt::format("links <= {:g} Mbit/s: qvr >= {:.2f}x best fixed", kSlowLinkMbps, kNearBest),
        countVerdicts(slow, &ConditionVerdict::qvr_over_best,
                      [](const auto&, double x) { return x >= kNearBest; })));
    out.back().detail += " (slow links only)";
    const ErrorStats plain = errorStats(r, &DesignReading::fpsErrorPct);
    const ErrorStats probed = errorStats(r, &DesignReading::fpsErrorAtProbeSpeedPct);
    // Beside the bar, not in it: the same runs' errors with the costs at the probes' speed.
    const std::string at_probe =
        probed.n == 0 ? ""
                      : fmt::format(
                            "; at the probes' speed {:.1f}% mean, {:.1f}% worst over the "
                            "{} runs with probes",
                            probed.mean(), probed.worst, probed.n);
    const std::string runs = fmt::format("over {} runs", plain.n);
    out.push_back({fmt::format("model FPS error mean <= {:g}%", kModelMeanPct),
                   plain.n > 0 && plain.mean() <= kModelMeanPct,
                   plain.n == 0 ? "not measured"
                                : fmt::format("{:.1f}% {}{}", plain.mean(), runs, at_probe)});
    out.push_back({fmt::format("model FPS error worst <= {:g}%", kModelWorstPct),
                   plain.n > 0 && plain.worst <= kModelWorstPct,
                   plain.n == 0 ? "not measured" : fmt::format("{:.1f}% {}", plain.worst, runs)});
    const int conditions = static_cast<int>(v.size());
    out.push_back({fmt::format("at least {} conditions", kMinConditions),
                   conditions >= kMinConditions, fmt::format("{} measured", conditions)});
    return out;
}

std::string sweepCsv(const SweepResult& r) {
    std::string s =
        "condition,scene,link,headset_share,motion,take,design,fps,frames,frames_reused,fresh_fps,"
        "mtp_ms_p99,bytes_per_frame,e1_deg,predicted_fps,fps_error_pct,"
        "predicted_fps_at_probe_speed,fps_error_at_probe_speed_pct\n";
    for (const SweepRow& row : r.rows) {
        const SweepCondition& c = r.conditions.at(static_cast<size_t>(row.condition));
        const DesignReading& d = row.reading;
        s += fmt::format(
            "{},{},{},{:g},{},{},{},{:.2f},{},{},{:.2f},{:.1f},{:.0f},{:.2f},{},{},{},{}\n",
            row.condition + 1, c.scene, c.link, c.headset_share, c.motion, row.take + 1, d.design,
            d.fps, d.frames, d.frames_reused, d.freshFps(), d.mtp_ms_p99, d.bytes_per_frame,
            d.e1_deg, cell(d.predicted_fps, "{:.2f}"), cell(d.fpsErrorPct(), "{:.1f}"),
            cell(d.predicted_fps_at_probe_speed, "{:.2f}"),
            cell(d.fpsErrorAtProbeSpeedPct(), "{:.1f}"));
    }
    return s;
}

std::string sweepMarkdown(const SweepOptions& o, const SweepResult& r) {
    std::string s = fmt::format(
        "# qvr sweep: seed {}, {} conditions, {} frames per design, {} repeat(s)\n\n"
        "{}; {:.0f} s. Adaptive designs {}; fixed grid {}°.{}\n\n"
        "## Conditions\n\nFPS here is of frames shown with their own layers (a frame that "
        "re-warped an older periphery is not counted); the best fixed e1 is the grid take's "
        "highest, judged on the repeats. *All frames*: qvr/best with every displayed frame "
        "counted.\n\n"
        "| # | scene | link | Mbit/s | headset share | motion | gaze seed | best "
        "fixed | qvr/best | all frames | qvr/ffr | qvr/aimd | MTP p99 qvr/best | FPS spread over "
        "takes |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        o.seed, o.conditions, o.frames, o.repeats, machineDescription(), r.seconds,
        fmt::join(o.adaptive, ", "), fmt::join(o.fixed_grid_deg, ", "),
        o.skipped_designs.empty()
            ? ""
            : fmt::format(" Skipped: {}.", fmt::join(o.skipped_designs, "; ")));
    for (const ConditionVerdict& v : r.verdicts) {
        const SweepCondition& c = r.conditions.at(static_cast<size_t>(v.condition));
        std::vector<std::string> spread;
        for (const auto& [d, pct] : v.spread_pct)
            spread.push_back(fmt::format("{} {:.0f}%", d, pct));
        s += fmt::format(
            "| {} | {} | {} | {} | {:g} | {} | {} | {} {:.1f} | {} | {} | {} | {} | {} | {} |\n",
            v.condition + 1, c.scene, linkLabel(c.link), cell(v.link_mbps, "{:.1f}"),
            c.headset_share, fs::path(c.motion).stem().string(), c.gaze_seed, v.best_fixed,
            v.best_fixed_fps, cell(v.qvr_over_best, "{:.2f}"),
            cell(v.qvr_over_best_all_frames, "{:.2f}"), cell(v.qvr_over_ffr, "{:.2f}"),
            cell(v.qvr_over_aimd, "{:.2f}"), cell(v.mtp_p99_over_best, "{:.2f}"),
            fmt::join(spread, ", "));
    }
    s += "\n## Criteria\n\n";
    for (const SweepCriterion& c : sweepCriteria(r))
        s += fmt::format("- {} {}: {}\n", c.pass ? "PASS" : "FAIL", c.name, c.detail);
    s += "\n## Every run\n\nFPS counts every displayed frame (what the model predicts); *own "
         "layers*: the frames shown with their own.\n\n| # | take | design | FPS | own layers | "
         "MTP p99 ms | bytes/frame | e1° | predicted FPS | error | error at the probes' speed |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SweepRow& row : r.rows) {
        const DesignReading& d = row.reading;
        s += fmt::format(
            "| {} | {} | {} | {:.1f} | {:.1f} | {:.0f} | {:.0f} | {:.1f} | {} | {} | "
            "{} |\n",
            row.condition + 1, row.take + 1, d.design, d.fps, d.freshFps(), d.mtp_ms_p99,
            d.bytes_per_frame, d.e1_deg, cell(d.predicted_fps, "{:.1f}"),
            cell(d.fpsErrorPct(), "{:+.1f}%"), cell(d.fpsErrorAtProbeSpeedPct(), "{:+.1f}%"));
    }
    if (r.failed_runs > 0 || r.stop_signal != 0)
        s += fmt::format(
            "\n{} run(s) failed{}.\n", r.failed_runs,
            r.stop_signal != 0 ? fmt::format("; stopped by signal {}", r.stop_signal) : "");
    return s;
}

json sweepJson(const SweepOptions& o, const SweepResult& r) {
    json j;
    j["seed"] = o.seed;
    j["frames"] = o.frames;
    j["repeats"] = o.repeats;
    j["adaptive"] = o.adaptive;
    j["fixed_grid_deg"] = o.fixed_grid_deg;
    j["skipped_designs"] = o.skipped_designs;
    j["seconds"] = r.seconds;
    j["failed_runs"] = r.failed_runs;
    json conditions = json::array();
    for (const SweepCondition& c : r.conditions)
        conditions.push_back({{"condition", c.index + 1},
                              {"scene", c.scene},
                              {"link", c.link},
                              {"headset_share", c.headset_share},
                              {"motion", c.motion},
                              {"gaze_seed", c.gaze_seed}});
    j["conditions"] = conditions;
    json verdicts = json::array();
    for (const ConditionVerdict& v : r.verdicts) {
        json spread = json::object();
        for (const auto& [d, pct] : v.spread_pct)
            spread[d] = pct;
        verdicts.push_back({{"condition", v.condition + 1},
                            {"link_mbps", optJson(v.link_mbps)},
                            {"best_fixed", v.best_fixed},
                            {"best_fixed_fps", v.best_fixed_fps},
                            {"qvr_over_best_fixed", optJson(v.qvr_over_best)},
                            {"qvr_over_best_fixed_all_frames", optJson(v.qvr_over_best_all_frames)},
                            {"qvr_over_ffr", optJson(v.qvr_over_ffr)},
                            {"qvr_over_aimd", optJson(v.qvr_over_aimd)},
                            {"mtp_p99_over_best_fixed", optJson(v.mtp_p99_over_best)},
                            {"fps_spread_pct", spread}});
    }
    j["verdicts"] = verdicts;
    json runs = json::array();
    for (const SweepRow& row : r.rows) {
        const DesignReading& d = row.reading;
        runs.push_back({{"condition", row.condition + 1},
                        {"take", row.take + 1},
                        {"design", d.design},
                        {"fps", d.fps},
                        {"frames", d.frames},
                        {"frames_reused", d.frames_reused},
                        {"fresh_fps", d.freshFps()},
                        {"mtp_ms_p99", d.mtp_ms_p99},
                        {"bytes_per_frame", d.bytes_per_frame},
                        {"e1_deg", d.e1_deg},
                        {"predicted_fps", optJson(d.predicted_fps)},
                        {"fps_error_pct", optJson(d.fpsErrorPct())},
                        {"predicted_fps_at_probe_speed", optJson(d.predicted_fps_at_probe_speed)},
                        {"fps_error_at_probe_speed_pct", optJson(d.fpsErrorAtProbeSpeedPct())}});
    }
    j["runs"] = runs;
    json criteria = json::array();
    for (const SweepCriterion& c : sweepCriteria(r))
        criteria.push_back({{"criterion", c.name}, {"pass", c.pass}, {"detail", c.detail}});
    j["criteria"] = criteria;
    return j;
}

int runSweep(const SweepOptions& o, ConditionRunner& runner, std::FILE* out, std::FILE* err) {
    std::error_code ec;
    fs::create_directories(o.out, ec);
    if (ec) {
        fmt::print(err, "qvr sweep: cannot create '{}': {}\n", o.out, ec.message());
        return 1;
    }
    fmt::print(out, "qvr sweep: seed {}, {} conditions, designs {} and fixed {}°, {} repeat(s)\n",
               o.seed, o.conditions, fmt::join(o.adaptive, ","), fmt::join(o.fixed_grid_deg, ","),
               o.repeats);
    if (o.dry_run) {
        for (const SweepCondition& c : drawConditions(o.space, o.seed, o.conditions))
            fmt::print(out, "  {:2} {} | {} | share {:g} | {} | seed {} | {}\n", c.index + 1,
                       c.scene, c.link, c.headset_share, c.motion, c.gaze_seed,
                       fmt::join(takeDesigns(o, c.index, 0, ""), ","));
        return 0;
    }
    const SweepResult result = executeSweep(o, runner, out);
    const std::string md = sweepMarkdown(o, result);
    fmt::print(out, "\n{}", md);
    const fs::path dir(o.out);
    for (const Status& st : {writeTextFile((dir / "sweep.md").string(), md),
                             writeTextFile((dir / "sweep.csv").string(), sweepCsv(result)),
                             writeJsonFile((dir / "sweep.json").string(), sweepJson(o, result))})
        if (!st)
            fmt::print(err, "qvr sweep: {}\n", st.error());
    fmt::print(out, "  wrote {}/sweep.md, sweep.csv and sweep.json\n", o.out);
    if (result.stop_signal != 0) {
        fmt::print(err, "qvr sweep: stopped by signal {}\n", result.stop_signal);
        return 130;
    }
    return result.failed_runs > 0 ? 1 : 0;
}

}  // namespace qvr::experiment
