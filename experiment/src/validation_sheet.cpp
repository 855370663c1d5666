// The correlation sheet from its result: the cells read from each run's summary.json, the
// speed probes' verdict on each take, the aggregate errors, validation.md and validation.json
// (validation.h).
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "qvr/experiment/calibration.h"
#include "qvr/experiment/validation.h"

namespace qvr::experiment {

namespace {

using nlohmann::json;

double mean(const std::vector<double>& v) {
    if (v.empty())
        return NAN;
    double s = 0;
    for (double x : v)
        s += x;
    return s / double(v.size());
}

double spread(const std::vector<double>& v) {  // max − min
    if (v.size() < 2)
        return 0.0;
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi - *lo;
}

std::string cell(double v, const char* f) {
    return std::isfinite(v) ? fmt::format(fmt::runtime(f), v) : std::string("—");
}

// A number at `key` of an object (NaN when absent or not a number).
double num(const json& object, const char* key) {
    if (!object.is_object())
        return NAN;
    const auto it = object.find(key);
    return it != object.end() && it->is_number() ? it->get<double>() : NAN;
}

const json& member(const json& object, const char* key) {
    static const json kNull;
    if (!object.is_object())
        return kNull;
    const auto it = object.find(key);
    return it != object.end() ? *it : kNull;
}

std::string cellKey(const std::string& scene, const std::string& link, int depth,
                    const std::string& motion, double headset_share, const std::string& design) {
    return fmt::format("{}|{}|{}|{}|{:g}|{}", scene, link, depth, motion, headset_share, design);
}

}  // namespace

void ValidationRows::add(const json& summary, const std::string& scene, const std::string& link,
                         int depth, const std::string& motion, double headset_share) {
    const json& designs = member(summary, "designs");
    if (!designs.is_object())
        return;
    for (auto it = designs.begin(); it != designs.end(); ++it) {
        const json& d = it.value();
        if (!d.is_object() || !d.contains("prediction_error_pct"))
            continue;
        const std::string key = cellKey(scene, link, depth, motion, headset_share, it.key());
        auto [slot, added] = m_index.try_emplace(key, m_rows.size());
        if (added) {
            ValidationRow row;
            row.scene = scene;
            row.link = link;
            row.design = it.key();
            row.depth = depth;
            row.motion = motion;
            row.headset_share = headset_share;
            m_rows.push_back(std::move(row));
        }
        ValidationRow& r = m_rows[slot->second];
        const json& e = d["prediction_error_pct"];
        r.fps_error_pct.push_back(num(e, "fps_mean"));
        r.mtp_error_pct.push_back(num(e, "mtp_ms_mean"));
        r.bytes_error_pct.push_back(num(e, "bytes_per_frame_mean"));
        r.e1_error_deg.push_back(num(member(d, "prediction_error_abs"), "e1_deg_mean"));
        r.fps_measured.push_back(num(d, "fps_mean"));
        r.fps_predicted.push_back(num(member(d, "predicted"), "fps_mean"));
        r.headset_cost_error_pct.push_back(num(e, "headset_busy_ms_mean"));
        r.server_cost_error_pct.push_back(num(e, "server_busy_ms_mean"));
        if (d.contains("prediction_error_pct_at_probe_speed"))
            r.fps_error_pct_at_probe_speed.push_back(
                num(d["prediction_error_pct_at_probe_speed"], "fps_mean"));
    }
}

const ValidationRow* ValidationRows::find(const ValidationRow& row) const {
    const auto it = m_index.find(
        cellKey(row.scene, row.link, row.depth, row.motion, row.headset_share, row.design));
    return it == m_index.end() ? nullptr : &m_rows[it->second];
}

int validationExitCode(const ValidationResult& result) {
    if (result.aborted_exit != 0)
        return result.aborted_exit;
    if (result.stop_signal != 0)
        return 130;
    return result.failed_runs > 0 ? 1 : 0;
}

double runDisturbancePct(const json& summary) {
    const json& sp = member(member(summary, "calibration"), "speed_reference");
    const json& spread_pct = member(sp, "run_spread_pct");
    const json& over = member(sp, "run_over_reference");
    if (!over.is_object())  // no probes were taken: run_spread_pct is 0 then, not a reading
        return NAN;
    double d = NAN;
    for (const char* side : {"headset", "server"}) {
        if (const double s = num(spread_pct, side); !std::isnan(s))
            d = std::fmax(d, s);
        if (const double o = num(over, side); !std::isnan(o))
            d = std::fmax(d, 100.0 * std::fabs(o - 1.0));
    }
    return d;
}

double runSpeedSpreadPct(const json& summary) {
    const json& spread_pct =
        member(member(member(summary, "calibration"), "speed_reference"), "run_spread_pct");
    const double h = num(spread_pct, "headset"), s = num(spread_pct, "server");
    return std::isfinite(h) && std::isfinite(s) ? std::max(h, s) : NAN;
}

double calibrationSpreadPct(const json& calibration) {
    if (calibration.is_discarded() || !calibration.is_object())
        return NAN;
    const json& probes = member(member(calibration, "speed_reference"), "probes");
    if (!probes.is_array() || probes.size() < 2)
        return NAN;
    std::vector<SpeedSample> samples;
    for (const json& p : probes) {
        SpeedSample s;
        s.headset_ms = p.value("headset_frame_ms", NAN);
        s.server_ms = p.value("server_frame_ms", NAN);
        if (!(s.headset_ms > 0.0) || !(s.server_ms > 0.0))
            return NAN;
        samples.push_back(s);
    }
    const auto sp = speedProbesSpreadPct(samples);
    return std::max(sp[0], sp[1]);
}

bool steadyByProbes(double pct) {
    return !std::isfinite(pct) || pct <= kUnsteadySpeedPct;
}

bool steadierTake(double pct, double best_pct) {
    return !(pct >= best_pct);
}

std::string takeNote(double pct, bool more_takes) {
    if (!std::isfinite(pct))
        return {};
    return fmt::format(" (speed moved {:.0f}%{})", pct,
                       steadyByProbes(pct) ? ""
                       : more_takes        ? ": unsteady, again"
                                           : ": unsteady");
}

AbsError absError(const ValidationRows& order, const ValidationRows& table,
                  std::vector<double> ValidationRow::*field) {
    std::vector<double> abs;
    for (const ValidationRow& key : order.rows())
        if (const ValidationRow* r = table.find(key))
            if (const double m = mean(r->*field); std::isfinite(m))
                abs.push_back(std::fabs(m));
    AbsError e;
    e.cells = abs.size();
    if (!abs.empty()) {
        e.mean = mean(abs);
        e.worst = *std::max_element(abs.begin(), abs.end());
    }
    return e;
}

ValidationStats summariseValidation(const ValidationResult& result) {
    const ValidationRows& rows = result.rows;
    ValidationStats s;
    s.fps = absError(rows, rows, &ValidationRow::fps_error_pct);
    s.mtp = absError(rows, rows, &ValidationRow::mtp_error_pct);
    s.bytes = absError(rows, rows, &ValidationRow::bytes_error_pct);
    s.e1 = absError(rows, rows, &ValidationRow::e1_error_deg);
    s.fps_at_probe_speed = absError(rows, rows, &ValidationRow::fps_error_pct_at_probe_speed);
    s.fps_first_takes = absError(rows, result.rows_first_takes, &ValidationRow::fps_error_pct);
    s.fps_steady = absError(rows, result.rows_steady, &ValidationRow::fps_error_pct);
    s.mtp_steady = absError(rows, result.rows_steady, &ValidationRow::mtp_error_pct);
    std::vector<double> every;
    for (const ValidationRow& r : rows.rows())
        for (double e : r.fps_error_pct)
            if (std::isfinite(e))
                every.push_back(std::fabs(e));
    s.fps_every_run.cells = every.size();
    if (!every.empty()) {
        s.fps_every_run.mean = mean(every);
        s.fps_every_run.worst = *std::max_element(every.begin(), every.end());
    }
    std::vector<double> v = result.run_speed_spread_pct;
    if (!v.empty()) {
        std::sort(v.begin(), v.end());
        s.run_speed_spread_median_pct = v[v.size() / 2];
    }
    s.runs_unsteady = static_cast<size_t>(
        std::count_if(v.begin(), v.end(), [](double x) { return x > kUnsteadySpeedPct; }));
    return s;
}

namespace {

// The cell's condition beyond scene, link and depth: its motion and headset share when not the
// defaults.
std::string conditionLabel(const ValidationRow& r) {
    std::string s = r.scene;
    if (r.motion != "default")
        s += " · " + std::filesystem::path(r.motion).stem().string();
    if (r.headset_share < 1.0)
        s += fmt::format(" · share {:g}", r.headset_share);
    return s;
}

std::string linkLabel(const std::string& link) {
    return link.rfind("trace:", 0) == 0
               ? "trace:" + std::filesystem::path(link.substr(6)).filename().string()
               : link;
}

// Every run of every cell: its own error, not the cell's mean.
std::string everyRunTable(const ValidationRows& rows) {
    std::string md =
        "| scene | link | depth | design | run | FPS measured | FPS predicted | FPS error |\n"
        "|---|---|---|---|---|---|---|---|\n";
    for (const ValidationRow& r : rows.rows())
        for (size_t i = 0; i < r.fps_error_pct.size(); ++i)
            md += fmt::format(
                "| {} | {} | {} | {} | {} | {} | {} | {} |\n", conditionLabel(r), linkLabel(r.link),
                r.depth, r.design, i + 1, cell(r.fps_measured.at(i), "{:.1f}"),
                cell(r.fps_predicted.at(i), "{:.1f}"), cell(r.fps_error_pct[i], "{:+.1f}%"));
    return md;
}

std::string markdownTable(const ValidationRows& rows) {
    std::string md = fmt::format(
        "| scene | link | depth | design | FPS measured | FPS predicted | FPS error | MTP error | "
        "bytes error | e1 error | FPS spread over reps | headset cost error | server cost error "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const ValidationRow& r : rows.rows()) {
        md += fmt::format(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            conditionLabel(r), linkLabel(r.link), r.depth, r.design,
            cell(mean(r.fps_measured), "{:.1f}"), cell(mean(r.fps_predicted), "{:.1f}"),
            cell(mean(r.fps_error_pct), "{:+.1f}%"), cell(mean(r.mtp_error_pct), "{:+.1f}%"),
            cell(mean(r.bytes_error_pct), "{:+.1f}%"), cell(mean(r.e1_error_deg), "{:+.1f}°"),
            cell(spread(r.fps_measured), "{:.1f}"),
            cell(mean(r.headset_cost_error_pct), "{:+.1f}%"),
            cell(mean(r.server_cost_error_pct), "{:+.1f}%"));
    }
    return md;
}

// "MEAN (WORST)" of an AbsError in `f`.
std::string meanWorst(const AbsError& e, const char* f) {
    return fmt::format("{} ({})", cell(e.mean, f), cell(e.worst, f));
}

}  // namespace

std::string validationMarkdown(const ValidationPlan& plan, const ValidationResult& result) {
    const ValidationStats s = summariseValidation(result);
    std::string md = markdownTable(result.rows);
    md += fmt::format(
        "\nMean absolute error (worst): FPS {}, MTP mean {}, bytes/frame {}, e1 {} over {} "
        "design × condition cells; {} failed runs; {:.0f} s.\n",
        meanWorst(s.fps, "{:.1f}%"), meanWorst(s.mtp, "{:.1f}%"), meanWorst(s.bytes, "{:.1f}%"),
        meanWorst(s.e1, "{:.1f}°"), result.rows.rows().size(), result.failed_runs, result.seconds);
    md += fmt::format(
        "The steady runs alone ({} of {}: speed probes within 10% across the run and of the "
        "calibration's reference; a run without probes is not judged): FPS {}, MTP mean {} over "
        "{} cells.\n",
        result.runs_steady, result.runs_counted, meanWorst(s.fps_steady, "{:.1f}%"),
        meanWorst(s.mtp_steady, "{:.1f}%"), s.fps_steady.cells);
    md += fmt::format(
        "Runs taken again because their speed probes moved over 10% (across the run or from "
        "the calibration's reference): {} (up to {} per run); still unsteady after them: {} of "
        "{}. The first takes alone: FPS {}.\n",
        result.runs_retaken, plan.options.retakes, result.runs_unsteady_after_retakes,
        result.runs_counted, meanWorst(s.fps_first_takes, "{:.1f}%"));
    md += fmt::format(
        "With each design's costs at its speed probes' speed (predicted_at_probe_speed): FPS {}. "
        "The speed probes moved by a median {} over a run, over 10% in {} of {} runs.\n",
        meanWorst(s.fps_at_probe_speed, "{:.1f}%"), cell(s.run_speed_spread_median_pct, "{:.1f}%"),
        s.runs_unsteady, result.run_speed_spread_pct.size());
    md += fmt::format(
        "Every run on its own (not a cell's mean over repetitions): FPS {} over {} runs.\n\n{}",
        meanWorst(s.fps_every_run, "{:.1f}%"), s.fps_every_run.cells, everyRunTable(result.rows));
    if (result.stop_signal != 0)
        md += fmt::format("Stopped by a signal: the sheet has the {} runs that ended of {}.\n",
                          result.runs_counted, plan.runs.size());
    return md;
}

namespace {

json rowsJson(const ValidationRows& rows) {
    json out = json::array();
    for (const ValidationRow& r : rows.rows())
        out.push_back({{"scene", r.scene},
                       {"link", r.link},
                       {"depth", r.depth},
                       {"motion", r.motion},
                       {"headset_share", r.headset_share},
                       {"design", r.design},
                       {"fps_measured", r.fps_measured},
                       {"fps_predicted", r.fps_predicted},
                       {"fps_error_pct", r.fps_error_pct},
                       {"mtp_error_pct", r.mtp_error_pct},
                       {"bytes_error_pct", r.bytes_error_pct},
                       {"e1_error_deg", r.e1_error_deg},
                       {"headset_cost_error_pct", r.headset_cost_error_pct},
                       {"server_cost_error_pct", r.server_cost_error_pct},
                       {"fps_error_pct_at_probe_speed", r.fps_error_pct_at_probe_speed}});
    return out;
}

json calibrationsJson(const std::vector<CalibrationRecord>& calibrations) {
    json out = json::array();
    for (const CalibrationRecord& c : calibrations)
        out.push_back({{"scene", c.scene},
                       {"rep", c.rep},
                       {"file", c.file},
                       {"probe_spread_pct", c.probe_spread_pct}});
    return out;
}

}  // namespace

json validationJson(const ValidationPlan& plan, const ValidationResult& result) {
    const ValidationStats s = summariseValidation(result);
    std::vector<double> calibration_spread;
    for (const CalibrationRecord& c : result.calibrations)
        calibration_spread.push_back(c.probe_spread_pct);
    return {{"machine", result.machine},
            {"seconds", result.seconds},
            {"reps", plan.options.reps},
            {"frames", plan.options.frames},
            {"failed_runs", result.failed_runs},
            {"fps_abs_error_pct_mean", s.fps.mean},
            {"fps_abs_error_pct_worst", s.fps.worst},
            {"mtp_abs_error_pct_mean", s.mtp.mean},
            {"mtp_abs_error_pct_worst", s.mtp.worst},
            {"bytes_abs_error_pct_mean", s.bytes.mean},
            {"bytes_abs_error_pct_worst", s.bytes.worst},
            {"e1_abs_error_deg_mean", s.e1.mean},
            {"e1_abs_error_deg_worst", s.e1.worst},
            {"fps_abs_error_pct_mean_at_probe_speed", s.fps_at_probe_speed.mean},
            {"fps_abs_error_pct_worst_at_probe_speed", s.fps_at_probe_speed.worst},
            {"run_speed_spread_pct", result.run_speed_spread_pct},
            {"runs_unsteady", s.runs_unsteady},
            {"retakes_max", plan.options.retakes},
            {"calibrate", calibrationPolicyName(plan.policy)},
            {"calibrations", calibrationsJson(result.calibrations)},
            {"calibration_probe_spread_pct", calibration_spread},
            {"runs_retaken", result.runs_retaken},
            {"runs_unsteady_after_retakes", result.runs_unsteady_after_retakes},
            {"run_disturbance_pct", result.run_disturbance_pct},
            {"fps_abs_error_pct_mean_first_takes", s.fps_first_takes.mean},
            {"runs_steady", result.runs_steady},
            {"fps_abs_error_pct_mean_steady_runs", s.fps_steady.mean},
            {"fps_abs_error_pct_worst_steady_runs", s.fps_steady.worst},
            {"mtp_abs_error_pct_mean_steady_runs", s.mtp_steady.mean},
            {"fps_abs_error_pct_worst_first_takes", s.fps_first_takes.worst},
            {"fps_abs_error_pct_mean_every_run", s.fps_every_run.mean},
            {"fps_abs_error_pct_worst_every_run", s.fps_every_run.worst},
            {"calibration_scene", plan.options.calibration_scene},
            {"motions", plan.options.motions},
            {"headset_shares", plan.options.headset_shares},
            {"rows", rowsJson(result.rows)}};
}

}  // namespace qvr::experiment
