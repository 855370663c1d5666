// The correlation sheet's plan: its calibrations and runs in order, and the command line of
// each take (validation.h).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "qvr/core/enum_table.h"
#include "qvr/core/shell_quote.h"

#include "qvr/experiment/validation.h"
#include "qvr/runtime/server_process.h"

namespace qvr::experiment {

namespace fs = std::filesystem;

namespace {

// A scene or link as a file name: its last 40 characters, [A-Za-z0-9-] kept, the rest '_'.
std::string safeName(const std::string& s) {
    std::string out;
    for (char c : s)
        out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-') ? c : '_';
    return out.size() > 40 ? out.substr(out.size() - 40) : out;
}

void addRuns(ValidationPlan& plan, const std::string& scene, int rep, size_t calibration) {
    for (const std::string& link : plan.options.links)
        for (int depth : plan.options.depths)
            for (const std::string& motion : plan.options.motions)
                for (double share : plan.options.headset_shares) {
                    plan.steps.push_back({PlannedStep::Kind::kRun, plan.runs.size()});
                    plan.runs.push_back({scene, link, depth, motion, share, rep, calibration});
                }
}

// A run's motion and share in its folder's name, when not the defaults.
std::string conditionSuffix(const PlannedRun& r) {
    std::string s;
    if (r.motion != "default")
        s += "_m" + safeName(fs::path(r.motion).stem().string());
    if (r.headset_share < 1.0)
        s += fmt::format("_s{:g}", r.headset_share);
    return s;
}

size_t addCalibration(ValidationPlan& plan, const std::string& scene, int rep) {
    plan.steps.push_back({PlannedStep::Kind::kCalibration, plan.calibrations.size()});
    plan.calibrations.push_back({scene, rep});
    return plan.calibrations.size() - 1;
}

}  // namespace

const char* calibrationPolicyName(CalibrationPolicy policy) {
    static constexpr EnumName<CalibrationPolicy> kNames[] = {
        {CalibrationPolicy::kPerRep, "per-rep"},
        {CalibrationPolicy::kOnce, "once"},
        {CalibrationPolicy::kGiven, "hardware"}};
    return enumName(kNames, policy);
}

size_t ValidationPlan::conditions() const {
    return options.links.size() * options.scenes.size() * options.depths.size() *
           options.motions.size() * options.headset_shares.size();
}

ValidationPlan planValidation(const ValidationOptions& options) {
    ValidationPlan plan;
    plan.options = options;
    plan.policy = !options.hardware.empty() ? CalibrationPolicy::kGiven : options.calibrate;
    const std::vector<std::string>& scenes = options.scenes;
    if (!options.calibration_scene.empty()) {  // one calibration predicts every scene
        size_t c = 0;
        for (int rep = 0; rep < options.reps; ++rep) {
            if (rep == 0 || plan.policy == CalibrationPolicy::kPerRep)
                c = addCalibration(plan, options.calibration_scene,
                                   plan.policy == CalibrationPolicy::kPerRep ? rep : 0);
            for (const std::string& scene : scenes)
                addRuns(plan, scene, rep, c);
        }
        return plan;
    }
    if (plan.policy == CalibrationPolicy::kPerRep) {
        for (int rep = 0; rep < options.reps; ++rep)
            for (const std::string& scene : scenes)
                addRuns(plan, scene, rep, addCalibration(plan, scene, rep));
        return plan;
    }
    for (const std::string& scene : scenes)
        addCalibration(plan, scene, 0);
    for (int rep = 0; rep < options.reps; ++rep)
        for (size_t s = 0; s < scenes.size(); ++s)
            addRuns(plan, scenes[s], rep, s);
    return plan;
}

ChildCommand calibrationTake(const ValidationPlan& plan, size_t calibration, int take) {
    const ValidationOptions& o = plan.options;
    const PlannedCalibration& c = plan.calibrations.at(calibration);
    ChildCommand cmd;
    cmd.output = (fs::path(o.out) / fmt::format("calibration-{}{}{}.toml", safeName(c.scene),
                                                c.rep == 0 ? "" : fmt::format("-r{}", c.rep + 1),
                                                take == 0 ? "" : fmt::format("-t{}", take + 1)))
                     .string();
    cmd.log_path = cmd.output + ".log";
    cmd.result_path = cmd.output + ".json";
    cmd.line = fmt::format("{} calibrate --scene {} --profile {} --out {} > {} 2>&1",
                           shellQuote(o.executable), shellQuote(c.scene), shellQuote(o.profile),
                           shellQuote(cmd.output), shellQuote(cmd.log_path));
    return cmd;
}

ChildCommand runChildIn(std::string output) {
    ChildCommand cmd;
    cmd.output = std::move(output);
    cmd.log_path = cmd.output + ".log";
    cmd.result_path = (fs::path(cmd.output) / "summary.json").string();
    return cmd;
}

ChildCommand runTake(const ValidationPlan& plan, size_t run, int take,
                     const std::string& calibration_file) {
    const ValidationOptions& o = plan.options;
    const PlannedRun& r = plan.runs.at(run);
    ChildCommand cmd = runChildIn(
        (fs::path(o.out) / fmt::format("{}_{}_d{}{}_r{}{}", safeName(r.scene), safeName(r.link),
                                       r.depth, conditionSuffix(r), r.rep + 1,
                                       take == 0 ? "" : fmt::format("_t{}", take + 1)))
            .string());
    cmd.line = fmt::format(
        "{} run --scene {} --net {} --pipeline {} --designs {} --frames {} --profile {} "
        "--hardware {}{}{} --no-video --out {} > {} 2>&1",
        shellQuote(o.executable), shellQuote(r.scene), shellQuote(r.link), r.depth,
        shellQuote(o.designs), o.frames, shellQuote(o.profile), shellQuote(calibration_file),
        r.motion == "default" ? "" : " --motion " + shellQuote(r.motion),
        r.headset_share < 1.0 ? fmt::format(" --headset-share {:g}", r.headset_share) : "",
        shellQuote(cmd.output), shellQuote(cmd.log_path));
    return cmd;
}

std::vector<std::string> mahimahiTraceFolders() {
    std::error_code ec;
    std::vector<fs::path> starts = {fs::current_path(ec)};
    if (auto exe = runtime::selfExecutable(); exe)
        starts.push_back(fs::path(*exe).parent_path());
    std::vector<std::string> out;
    for (const fs::path& start : starts)
        for (fs::path p = start; !p.empty(); p = p.parent_path()) {
            for (const fs::path& c : {p / "shared" / "data" / "network", p / "data" / "network"})
                if (fs::is_directory(c, ec) &&
                    std::find(out.begin(), out.end(), c.string()) == out.end())
                    out.push_back(c.string());
            if (p == p.parent_path())
                break;
        }
    return out;
}

std::string findMahimahiTrace(const std::string& file) {
    std::error_code ec;
    for (const std::string& folder : mahimahiTraceFolders())
        if (const fs::path c = fs::path(folder) / file; fs::exists(c, ec))
            return c.string();
    return {};
}

}  // namespace qvr::experiment
