// The sweep's plan: the space and its defaults, the options checked, the conditions drawn from
// a seed and the designs of each take (sweep.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include <fmt/format.h>

#include "qvr/core/design.h"
#include "qvr/core/link_spec.h"
#include "qvr/experiment/sweep.h"

namespace qvr::experiment {

namespace fs = std::filesystem;

namespace {

// The OpenArena levels, glTF model and CMU motions of the default space: what the repository's
// workload suite and scene tests use (data/workloads/suite.txt, tests/scene).
constexpr const char* kDefaultScenes =
    "builtin:room,openarena:oa_dm5,openarena:oa_dm1,"
    "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
constexpr const char* kDefaultMotions =
    "/usr/share/assimp/models/BVH/01_01.bvh,/usr/share/assimp/models/BVH/01_03.bvh,"
    "/usr/share/assimp/models/BVH/Boxing_Toes.bvh";
constexpr const char* kSharedTraces[] = {"ATT-LTE-driving-2016.down", "TMobile-LTE-short.down",
                                         "Verizon-LTE-short.down"};
// The shared traces' shape also at a slow mean, where the claim was found to fail.
constexpr double kSlowTraceMbps = 2.0;

std::vector<std::string> splitItems(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t comma = s.find(',', start);
        std::string item = s.substr(start, comma == std::string::npos ? comma : comma - start);
        if (!item.empty())
            out.push_back(std::move(item));
        if (comma == std::string::npos)
            break;
        start = comma + 1;
    }
    return out;
}

// A folder's *.down files, sorted.
std::vector<std::string> traceFilesIn(const fs::path& folder) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec))
        if (entry.is_regular_file(ec) && entry.path().extension() == ".down")
            out.push_back(entry.path().string());
    std::sort(out.begin(), out.end());
    return out;
}

// [0, 1) from the top 53 bits: the same on every standard library.
double unit(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

size_t pick(std::mt19937_64& rng, size_t n) {
    return std::min(n - 1, static_cast<size_t>(unit(rng) * static_cast<double>(n)));
}

// A rate to three significant digits, as `rate:` writes it.
std::string rateLink(double mbps) {
    const double scale = std::pow(10.0, 2 - std::floor(std::log10(mbps)));
    return fmt::format("rate:{:g}", std::round(mbps * scale) / scale);
}

Expected<std::vector<std::string>> traceLinks(const std::string& list) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const std::string& item : splitItems(list)) {
        if (item.rfind("trace:", 0) == 0) {
            if (auto spec = loadLinkSpec(item); !spec)
                return makeError(fmt::format("--traces: {}", spec.error()));
            out.push_back(item);
        } else if (fs::is_directory(item, ec)) {
            for (const std::string& f : traceFilesIn(item))
                out.push_back("trace:" + f);
        } else if (fs::is_regular_file(item, ec)) {
            if (auto spec = loadLinkSpec("trace:" + item); !spec)
                return makeError(fmt::format("--traces: {}", spec.error()));
            out.push_back("trace:" + item);
        } else {
            return makeError(fmt::format(
                "--traces: '{}' is no Mahimahi file, folder of *.down files or trace: spec", item));
        }
    }
    return out;
}

Expected<std::vector<double>> fixedGrid(const std::string& list) {
    std::vector<double> out;
    for (const std::string& item : splitItems(list)) {
        auto spec = parseDesign("fixed:" + item, DesignScope::Runtime);
        if (!spec)
            return makeError(fmt::format("--fixed-grid: {}", spec.error()));
        if (std::find(out.begin(), out.end(), spec->fixed_e1_deg) != out.end())
            return makeError(fmt::format("--fixed-grid: {} named twice", item));
        out.push_back(spec->fixed_e1_deg);
    }
    if (out.empty())
        return makeError(std::string("--fixed-grid: no e1 given"));
    return out;
}

Expected<std::vector<std::string>> adaptiveDesigns(const std::string& list,
                                                   std::vector<std::string>& skipped) {
    std::vector<std::string> out;
    for (const std::string& item : splitItems(list)) {
        auto spec = parseDesign(item, DesignScope::Runtime);
        if (!spec) {
            skipped.push_back(fmt::format("{} ({})", item, spec.error()));
            continue;
        }
        if (spec->design == Design::Fixed)
            return makeError(fmt::format("--designs: {}: fixed e1 belong in --fixed-grid", item));
        if (std::find(out.begin(), out.end(), spec->label()) != out.end())
            return makeError(fmt::format("--designs: {} named twice", item));
        out.push_back(spec->label());
    }
    if (std::find(out.begin(), out.end(), "qvr") == out.end())
        return makeError(std::string("--designs: the sweep judges qvr; name it"));
    return out;
}

// The items of the comma-separated `list` given as `option`: at least one, each a name
// `is_named` accepts or an existing file.
Expected<std::vector<std::string>> checkedInputs(const std::string& option, const std::string& list,
                                                 bool (*is_named)(const std::string&)) {
    std::vector<std::string> out = splitItems(list);
    std::error_code ec;
    for (const std::string& item : out)
        if (!is_named(item) && !fs::is_regular_file(item, ec))
            return makeError(fmt::format("{}: {}: no such file", option, item));
    if (out.empty())
        return makeError(fmt::format("{}: none given", option));
    return out;
}

Expected<std::vector<std::string>> checkedMotions(const std::string& list) {
    return checkedInputs("--motions", list,
                         [](const std::string& m) { return m == "default" || m == "still"; });
}

Expected<std::vector<std::string>> checkedScenes(const std::string& list) {
    // builtin:room, openarena:MAP, ...: a scene with a source prefix is not a file.
    return checkedInputs("--scenes", list,
                         [](const std::string& s) { return s.find(':') != std::string::npos; });
}

}  // namespace

std::vector<SweepCondition> drawConditions(const SweepSpace& space, uint64_t seed, int count) {
    std::mt19937_64 rng(seed);
    std::vector<SweepCondition> out;
    const double log_min = std::log(space.rate_min_mbps), log_max = std::log(space.rate_max_mbps);
    for (int i = 0; i < count; ++i) {
        SweepCondition c;
        c.index = i;
        // Every draw is taken whether used or not, so one choice never shifts the others.
        const double link_u = unit(rng), rate_u = unit(rng), trace_u = unit(rng);
        const double full_u = unit(rng), share_u = unit(rng);
        const double scene_u = unit(rng), motion_u = unit(rng);
        if (!space.traces.empty() && link_u < space.trace_odds)
            c.link = space.traces[std::min(space.traces.size() - 1,
                                           static_cast<size_t>(trace_u * space.traces.size()))];
        else
            c.link = rateLink(std::exp(log_min + rate_u * (log_max - log_min)));
        const double steps = std::floor((space.share_max - space.share_min) / 0.05 + 1e-9);
        c.headset_share = full_u < space.full_share_odds
                              ? 1.0
                              : space.share_min + 0.05 * std::floor(share_u * (steps + 1.0));
        c.headset_share = std::min(space.share_max, std::round(c.headset_share * 100.0) / 100.0);
        c.scene = space.scenes.empty()
                      ? "builtin:room"
                      : space.scenes[std::min(space.scenes.size() - 1,
                                              static_cast<size_t>(scene_u * space.scenes.size()))];
        c.motion =
            space.motions.empty()
                ? "default"
                : space.motions[std::min(space.motions.size() - 1,
                                         static_cast<size_t>(motion_u * space.motions.size()))];
        c.gaze_seed = 1 + pick(rng, 1000000);
        out.push_back(std::move(c));
    }
    return out;
}

std::optional<double> linkMeanMbps(const std::string& link) {
    auto spec = loadLinkSpec(link);
    if (!spec)
        return std::nullopt;
    if (spec->trace_target_bps > 0.0)
        return spec->trace_target_bps / 1e6;
    if (spec->trace)
        return spec->trace->meanBps() / 1e6;
    if (spec->rate_bps > 0.0)
        return spec->rate_bps / 1e6;
    return std::nullopt;
}

SweepArgs defaultSweepArgs() {
    SweepArgs a;
    std::vector<std::string> traces;
    for (const char* name : kSharedTraces)
        if (const std::string path = findMahimahiTrace(name); !path.empty()) {
            traces.push_back("trace:" + path);
            traces.push_back(fmt::format("trace:{}@{:g}", path, kSlowTraceMbps));
        }
    for (const std::string& folder : mahimahiTraceFolders())
        for (const std::string& f : traceFilesIn(folder))
            if (std::find(traces.begin(), traces.end(), "trace:" + f) == traces.end() &&
                std::none_of(std::begin(kSharedTraces), std::end(kSharedTraces),
                             [&](const char* n) { return fs::path(f).filename() == n; }))
                traces.push_back("trace:" + f);
    a.traces = fmt::format("{}", fmt::join(traces, ","));
    a.scenes = kDefaultScenes;
    a.motions = kDefaultMotions;
    a.designs = "qvr,sw,ffr,aimd";
    a.fixed_grid = "2,4,6,8,10,12,15,20";
    return a;
}

Expected<SweepOptions> sweepOptions(const SweepArgs& a) {
    SweepOptions o;
    if (a.conditions < 1 || a.conditions > 1000)
        return makeError(fmt::format("--conditions must be within 1..1000, got {}", a.conditions));
    if (a.repeats < 0 || a.repeats > 20)
        return makeError(fmt::format("--repeats must be within 0..20, got {}", a.repeats));
    if (!(a.share_min > 0.05 && a.share_min <= a.share_max && a.share_max <= 1.0))
        return makeError(fmt::format(
            "--share-min and --share-max must satisfy 0.05 < min <= max <= 1, got {:g} and {:g}",
            a.share_min, a.share_max));
    if (!(a.rate_min_mbps >= 0.01 && a.rate_min_mbps <= a.rate_max_mbps &&
          a.rate_max_mbps <= 10000.0))
        return makeError(fmt::format(
            "--rate-min and --rate-max must satisfy 0.01 <= min <= max <= 10000 Mbit/s, got "
            "{:g} and {:g}",
            a.rate_min_mbps, a.rate_max_mbps));
    auto traces = traceLinks(a.traces);
    auto grid = fixedGrid(a.fixed_grid);
    auto designs = adaptiveDesigns(a.designs, o.skipped_designs);
    auto scenes = checkedScenes(a.scenes);
    auto motions = checkedMotions(a.motions);
    if (!traces)
        return makeError(traces.error());
    if (!grid)
        return makeError(grid.error());
    if (!designs)
        return makeError(designs.error());
    if (!scenes)
        return makeError(scenes.error());
    if (!motions)
        return makeError(motions.error());
    o.seed = a.seed;
    o.conditions = a.conditions;
    o.space = {.rate_min_mbps = a.rate_min_mbps,
               .rate_max_mbps = a.rate_max_mbps,
               .traces = *traces,
               .share_min = a.share_min,
               .share_max = a.share_max,
               .scenes = *scenes,
               .motions = *motions};
    o.adaptive = *designs;
    o.fixed_grid_deg = *grid;
    o.repeats = a.repeats;
    o.frames = a.frames;
    o.hardware = a.hardware;
    o.cached_calibration = a.cached_calibration;
    o.profile = a.profile;
    o.out = a.out;
    o.dry_run = a.dry_run;
    if (!a.from.empty() && !fs::is_directory(a.from))
        return makeError(
            fmt::format("--from '{}' is not a folder of an earlier sweep's runs", a.from));
    o.from = a.from;
    return o;
}

std::vector<std::string> takeDesigns(const SweepOptions& o, int condition, int take,
                                     const std::string& best_fixed) {
    std::vector<std::string> designs = o.adaptive;
    if (take == 0) {
        for (double e1 : o.fixed_grid_deg)
            designs.push_back(designLabel(Design::Fixed, e1));
    } else if (!best_fixed.empty() &&
               std::find(designs.begin(), designs.end(), best_fixed) == designs.end()) {
        designs.push_back(best_fixed);
    }
    if (!designs.empty())
        std::rotate(designs.begin(),
                    designs.begin() +
                        static_cast<long>(static_cast<size_t>(condition + take) % designs.size()),
                    designs.end());
    return designs;
}

}  // namespace qvr::experiment
