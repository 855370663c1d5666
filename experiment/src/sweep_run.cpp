// The sweep taken: each condition's takes through a ConditionRunner, every run read from its
// summary.json, and each condition's verdicts from the medians of its takes (sweep.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "qvr/core/run_summary.h"
#include "qvr/core/shell_quote.h"
#include "qvr/experiment/sweep.h"

namespace qvr::experiment {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool isFixedLabel(const std::string& design) {
    return design == "ffr" || design.rfind("fixed:", 0) == 0;
}

// One condition's rows by design: every take's.
using ByDesign = std::map<std::string, std::vector<const SweepRow*>>;

double freshFpsOf(const DesignReading& r) {
    return r.freshFps();
}
double mtpP99Of(const DesignReading& r) {
    return r.mtp_ms_p99;
}

// The takes that ran both designs: the repeats, or the grid's take when no repeat ran both.
std::vector<int> commonTakes(const ByDesign& by, const std::string& a, const std::string& b) {
    const auto ia = by.find(a), ib = by.find(b);
    if (ia == by.end() || ib == by.end())
        return {};
    std::vector<int> both, repeats;
    for (const SweepRow* ra : ia->second)
        for (const SweepRow* rb : ib->second)
            if (ra->take == rb->take)
                both.push_back(ra->take);
    for (int t : both)
        if (t > 0)
            repeats.push_back(t);
    return repeats.empty() ? both : repeats;
}

std::optional<double> medianOver(const ByDesign& by, const std::string& design,
                                 const std::vector<int>& takes,
                                 double (*value)(const DesignReading&)) {
    std::vector<double> v;
    for (const SweepRow* r : by.at(design))
        if (std::find(takes.begin(), takes.end(), r->take) != takes.end())
            v.push_back(value(r->reading));
    if (v.empty())
        return std::nullopt;
    return median(v);
}

// a's median over b's, both over the takes that ran both (commonTakes).
std::optional<double> ratioOver(const ByDesign& by, const std::string& a, const std::string& b,
                                double (*value)(const DesignReading&) = freshFpsOf) {
    const std::vector<int> takes = commonTakes(by, a, b);
    if (takes.empty())
        return std::nullopt;
    const std::optional<double> x = medianOver(by, a, takes, value);
    const std::optional<double> y = medianOver(by, b, takes, value);
    if (!x || !y || (*y <= 0.0 && *x <= 0.0))
        return std::nullopt;
    // b showed none of its own frames and a did: a is ahead by any ratio.
    return *y <= 0.0 ? INFINITY : *x / *y;
}

// The fixed design (ffr is fixed:5) with the highest FPS in the condition's first take
// (beatsForBestFixed: ties to the lower MTP p99, then the name).
std::pair<std::string, double> bestFixedOf(const std::vector<SweepRow>& rows, int condition) {
    const DesignReading* best = nullptr;
    for (const SweepRow& r : rows) {
        if (r.condition != condition || r.take != 0 || !isFixedLabel(r.reading.design))
            continue;
        const DesignReading& d = r.reading;
        if (!best || beatsForBestFixed(d.freshFps(), d.mtp_ms_p99, d.design, best->freshFps(),
                                       best->mtp_ms_p99, best->design))
            best = &d;
    }
    if (!best || best->freshFps() <= 0.0)
        return {"", 0.0};
    return {best->design, best->freshFps()};
}

std::optional<double> errorPct(std::optional<double> predicted, double measured) {
    if (!predicted || measured <= 0.0)
        return std::nullopt;
    return 100.0 * (*predicted - measured) / measured;
}
// summary.json's designs.<d>.<object>.fps_mean, if it is a number.
std::optional<double> fpsMeanIn(const json& design, const char* object) {
    if (!design.contains(object) || !design[object].is_object())
        return std::nullopt;
    const json& o = design[object];
    if (!o.contains("fps_mean") || !o["fps_mean"].is_number())
        return std::nullopt;
    return o["fps_mean"].get<double>();
}
}  // namespace

std::optional<double> DesignReading::fpsErrorPct() const {
    return errorPct(predicted_fps, fps);
}
std::optional<double> DesignReading::fpsErrorAtProbeSpeedPct() const {
    return errorPct(predicted_fps_at_probe_speed, fps);
}
double DesignReading::freshFps() const {
    return ownLayersFps(fps, frames, frames_reused);
}

namespace {

DesignReading readingOf(const std::string& name, const json& d) {
    const auto num = [&](const char* key) {
        return d.contains(key) && d[key].is_number() ? d[key].get<double>() : 0.0;
    };
    DesignReading r;
    r.design = name;
    r.fps = num("fps_mean");
    r.mtp_ms_p99 = num("mtp_ms_p99");
    r.bytes_per_frame = num("bytes_per_frame_mean");
    r.e1_deg = num("e1_deg_mean");
    r.frames = static_cast<int>(std::clamp(num("frames"), 0.0, 1e9));
    r.frames_reused = static_cast<int>(std::clamp(num("frames_reused"), 0.0, double(r.frames)));
    r.predicted_fps = fpsMeanIn(d, "predicted");
    r.predicted_fps_at_probe_speed = fpsMeanIn(d, "predicted_at_probe_speed");
    return r;
}

const json* designsOf(const json& summary) {
    if (!summary.is_object() || !summary.contains("designs") || !summary["designs"].is_object())
        return nullptr;
    return &summary["designs"];
}

}  // namespace

std::vector<DesignReading> readingsFromSummary(const json& summary,
                                               const std::vector<std::string>& designs) {
    std::vector<DesignReading> out;
    if (const json* all = designsOf(summary))
        for (const std::string& name : designs)
            if (all->contains(name) && (*all)[name].is_object())
                out.push_back(readingOf(name, (*all)[name]));
    return out;
}

std::vector<DesignReading> readingsFromSummary(const json& summary) {
    std::vector<DesignReading> out;
    if (const json* all = designsOf(summary))
        for (const auto& [name, d] : all->items())
            if (d.is_object())
                out.push_back(readingOf(name, d));
    return out;
}

ConditionRun StoredConditionRunner::run(const SweepCondition&, const std::vector<std::string>&,
                                        const std::string& tag) {
    const fs::path path = fs::path(m_dir) / tag / "summary.json";
    ConditionRun out;
    std::ifstream f(path);
    if (!f) {
        out.note = fmt::format("no {}", path.string());
        return out;
    }
    out.designs = readingsFromSummary(json::parse(f, nullptr, false));
    out.ok = !out.designs.empty();
    if (!out.ok)
        out.note = fmt::format("{} holds no design", path.string());
    return out;
}

ChildCommand ProcessConditionRunner::command(const SweepCondition& c,
                                             const std::vector<std::string>& designs,
                                             const std::string& tag, bool recalibrate) const {
    const SweepOptions& o = m_options;
    ChildCommand cmd = runChildIn((fs::path(o.out) / tag).string());
    cmd.line = fmt::format(
        "{} run --scene {} --motion {} --seed {} --net {} --headset-share {:g} --designs {} "
        "--frames {} --profile {}{}{} --no-video --quality-every 0 --quiet --out {} > {} 2>&1",
        shellQuote(o.executable), shellQuote(c.scene), shellQuote(c.motion), c.gaze_seed,
        shellQuote(c.link), c.headset_share, shellQuote(fmt::format("{}", fmt::join(designs, ","))),
        o.frames, shellQuote(o.profile),
        o.hardware.empty() ? "" : " --hardware " + shellQuote(o.hardware),
        recalibrate ? " --recalibrate" : "", shellQuote(cmd.output), shellQuote(cmd.log_path));
    return cmd;
}

ConditionRun ProcessConditionRunner::run(const SweepCondition& c,
                                         const std::vector<std::string>& designs,
                                         const std::string& tag) {
    const bool recalibrate = m_options.hardware.empty() && !m_options.cached_calibration &&
                             m_calibrated.insert(c.scene).second;
    const ChildCommand cmd = command(c, designs, tag, recalibrate);
    ChildOutcome outcome = m_children.run(cmd);
    ConditionRun out;
    // A run that exits 1 (a design never showed the server's layers) still wrote its summary.
    if (outcome.result.is_null() && outcome.exit_code == 1) {
        std::ifstream f(cmd.result_path);
        outcome.result = json::parse(f, nullptr, false);
    }
    out.designs = readingsFromSummary(outcome.result, designs);
    out.ok = !out.designs.empty();
    if (!out.ok || outcome.exit_code != 0)
        out.note = fmt::format("exit {}, see {}", outcome.exit_code, cmd.log_path);
    return out;
}

std::vector<ConditionVerdict> conditionVerdicts(const SweepOptions& options,
                                                const SweepResult& result) {
    std::vector<ConditionVerdict> out;
    for (const SweepCondition& c : result.conditions) {
        ByDesign by;
        for (const SweepRow& r : result.rows)
            if (r.condition == c.index)
                by[r.reading.design].push_back(&r);
        if (by.empty())
            continue;
        ConditionVerdict v;
        v.condition = c.index;
        v.link_mbps = linkMeanMbps(c.link);
        std::tie(v.best_fixed, v.best_fixed_fps) = bestFixedOf(result.rows, c.index);
        v.qvr_over_best = ratioOver(by, "qvr", v.best_fixed);
        v.qvr_over_best_all_frames =
            ratioOver(by, "qvr", v.best_fixed, [](const DesignReading& r) { return r.fps; });
        v.qvr_over_ffr = ratioOver(by, "qvr", "ffr");
        v.qvr_over_aimd = ratioOver(by, "qvr", "aimd");
        v.mtp_p99_over_best = ratioOver(by, "qvr", v.best_fixed, mtpP99Of);
        std::vector<std::string> spread_designs = options.adaptive;
        if (!v.best_fixed.empty() && std::find(spread_designs.begin(), spread_designs.end(),
                                               v.best_fixed) == spread_designs.end())
            spread_designs.push_back(v.best_fixed);
        for (const std::string& d : spread_designs) {
            const auto it = by.find(d);
            if (it == by.end() || it->second.size() < 2)
                continue;
            std::vector<double> f;
            for (const SweepRow* r : it->second)
                f.push_back(r->reading.freshFps());
            const double m = median(f);
            if (m > 0.0)
                v.spread_pct.emplace_back(d, 100.0 *
                                                 (*std::max_element(f.begin(), f.end()) -
                                                  *std::min_element(f.begin(), f.end())) /
                                                 m);
        }
        out.push_back(std::move(v));
    }
    return out;
}

SweepResult executeSweep(const SweepOptions& o, ConditionRunner& runner, std::FILE* out) {
    const auto t0 = std::chrono::steady_clock::now();
    SweepResult result;
    result.conditions = drawConditions(o.space, o.seed, o.conditions);
    for (const SweepCondition& c : result.conditions) {
        std::string best;
        for (int take = 0; take <= o.repeats && runner.stopSignal() == 0; ++take) {
            const std::vector<std::string> designs = takeDesigns(o, c.index, take, best);
            const std::string tag = fmt::format("c{:02}_{}", c.index + 1,
                                                take == 0 ? "grid" : fmt::format("r{}", take + 1));
            fmt::print(out, "  condition {}/{} {} | {} | share {:g} | {} | take {}/{} ...",
                       c.index + 1, o.conditions, c.scene, c.link, c.headset_share,
                       fs::path(c.motion).stem().string(), take + 1, o.repeats + 1);
            std::fflush(out);
            const ConditionRun run = runner.run(c, designs, tag);
            if (runner.stopSignal() != 0) {
                fmt::print(out, " stopped\n");
                result.stop_signal = runner.stopSignal();
                break;
            }
            if (!run.ok) {
                ++result.failed_runs;
                fmt::print(out, " failed ({})\n", run.note);
                if (take == 0)
                    break;  // no grid: no best fixed to repeat
                continue;
            }
            for (const DesignReading& r : run.designs)
                result.rows.push_back({c.index, take, r});
            if (take == 0)
                best = bestFixedOf(result.rows, c.index).first;
            fmt::print(out, " done{}\n", take == 0 ? fmt::format(", best fixed {}", best) : "");
        }
        if (result.stop_signal != 0)
            break;
    }
    result.verdicts = conditionVerdicts(o, result);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

}  // namespace qvr::experiment
