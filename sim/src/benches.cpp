// The Table 3 suite by name: the recorded OpenArena workloads of data/workloads/ (listed in its
// suite.txt) or the workload part's synthetic generator.
#include "qvr/sim/benches.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include <fmt/format.h>

#include "qvr/workload/synthetic.h"
#include "qvr/workload/trace_io.h"

namespace qvr {

namespace fs = std::filesystem;

namespace {

// paperSyntheticSuite() lists Table 3's rows in order; these are Table 4's column labels.
constexpr std::array<const char*, 7> kLabels = {"D3H", "D3L", "H2H", "H2L", "GD", "UT3", "WF"};

struct RecordedEntry {
    std::string name;
    std::string level;
    std::string profile;
};

struct Selection {
    SuiteKind kind = SuiteKind::kSynthetic;
    std::string dir;
    std::vector<RecordedEntry> entries;
};

std::mutex g_mutex;
Selection g_selection;

Selection current() {
    std::lock_guard<std::mutex> lock(g_mutex);
    return g_selection;
}

// "oa-dm5-h" → "DM5-H": short enough for Table 4's columns.
std::string labelOf(const std::string& name) {
    std::string s = name.rfind("oa-", 0) == 0 ? name.substr(3) : name;
    for (char& c : s)
        c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

// suite.txt: '#' comments, then "name level profile motion gaze_seed frames" per line.
Expected<std::vector<RecordedEntry>> readSuiteList(const std::string& dir) {
    const fs::path list = fs::path(dir) / "suite.txt";
    std::ifstream in(list);
    if (!in)
        return makeError(
            fmt::format("no recorded suite: cannot read '{}' (record one with "
                        "scripts/record_suite.sh, or use --suite synthetic)",
                        list.string()));
    std::vector<RecordedEntry> out;
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (line.empty() || line[0] == '#')
            continue;
        std::istringstream fields(line);
        RecordedEntry e;
        if (!(fields >> e.name >> e.level >> e.profile))
            return makeError(
                fmt::format("{}:{}: expected 'name level profile …'", list.string(), line_no));
        if (!fs::exists(fs::path(dir) / (e.name + ".jsonl")))
            return makeError(fmt::format("{}:{}: '{}.jsonl' is missing from {}", list.string(),
                                         line_no, e.name, dir));
        out.push_back(e);
    }
    if (out.empty())
        return makeError(fmt::format("{}: lists no workloads", list.string()));
    return out;
}

// Forwards then backwards (n, …, 1, 0, 1, …) until `frames`, renumbered with the display
// rate's times, so poses and gaze stay continuous where the recording ends.
WorkloadTrace extendTrace(const WorkloadTrace& recorded, int frames) {
    WorkloadTrace out;
    out.header = recorded.header;
    const auto n = static_cast<int64_t>(recorded.frames.size());
    const double frame_ms = 1000.0 / recorded.header.profile.refresh_hz;
    for (int64_t i = 0; i < frames; ++i) {
        int64_t k = i;
        if (n > 1) {
            const int64_t period = 2 * (n - 1);
            k = i % period;
            if (k >= n)
                k = period - k;
        } else {
            k = 0;
        }
        WorkloadFrame f = recorded.frames[static_cast<size_t>(k)];
        f.index = i;
        f.time_ms = static_cast<double>(i) * frame_ms;
        out.frames.push_back(std::move(f));
    }
    return out;
}

std::string exeDir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string() : exe.parent_path().string();
}

}  // namespace

Status selectSuite(SuiteKind kind, const std::string& dir) {
    Selection s;
    s.kind = kind;
    if (kind == SuiteKind::kRecorded) {
        auto entries = readSuiteList(dir);
        if (!entries)
            return makeError(entries.error());
        s.dir = dir;
        s.entries = std::move(*entries);
    }
    std::lock_guard<std::mutex> lock(g_mutex);
    g_selection = std::move(s);
    return {};
}

SuiteKind selectedSuite() {
    return current().kind;
}

std::string findWorkloadsDir() {
    std::error_code ec;
    for (fs::path start : {fs::current_path(ec), fs::path(exeDir())}) {
        for (fs::path p = start; !p.empty(); p = p.parent_path()) {
            const fs::path candidate = p / "data" / "workloads";
            if (fs::exists(candidate / "suite.txt", ec))
                return candidate.string();
            if (p == p.parent_path())
                break;
        }
    }
    return {};
}

std::vector<BenchInfo> suiteBenches() {
    const Selection s = current();
    std::vector<BenchInfo> out;
    if (s.kind == SuiteKind::kRecorded) {
        for (const auto& e : s.entries)
            out.push_back({e.name, labelOf(e.name)});
        return out;
    }
    const auto suite = paperSyntheticSuite();
    for (size_t i = 0; i < suite.size(); ++i)
        out.push_back({suite[i].name, i < kLabels.size() ? kLabels[i] : suite[i].name});
    return out;
}

std::string suiteBenchNamesList() {
    std::string s;
    for (const auto& b : suiteBenches()) {
        if (!s.empty())
            s += ", ";
        s += b.name;
    }
    return s;
}

std::string suiteDescription() {
    const Selection s = current();
    if (s.kind == SuiteKind::kSynthetic)
        return "Workloads are the seeded <b>synthetic</b> stand-ins for Table 3's games, not the "
               "games.";
    std::string levels;
    for (const auto& e : s.entries) {
        if (!levels.empty())
            levels += ", ";
        levels += fmt::format("{} ({}{}, {})", e.name,
                              e.level.find(':') == std::string::npos ? "OpenArena " : "", e.level,
                              e.profile == "low" ? "1280&times;1600" : "1920&times;2160");
    }
    return fmt::format(
        "Workloads are <b>recorded</b> from OpenArena levels standing in for Table "
        "3's games and a chess set standing in for Table 1's Foveated3D scene "
        "(docs/RECORDING.md): {}.",
        levels);
}

Expected<WorkloadTrace> makeSuiteBench(const std::string& name, int frames, CodecModel codec) {
    if (frames <= 0 || frames > 1'000'000)
        return makeError(fmt::format("frames must be in 1..1000000, got {}", frames));
    for (SyntheticSpec spec : paperSyntheticSuite()) {
        if (spec.name == name || spec.name == "synthetic-" + name) {
            spec.frames = frames;
            return generateSyntheticWorkload(spec);
        }
    }
    const Selection s = current();
    for (const auto& e : s.entries) {
        if (e.name != name)
            continue;
        auto t = loadWorkloadTrace((fs::path(s.dir) / (e.name + ".jsonl")).string());
        if (!t)
            return makeError(t.error());
        if (Status st = applyCodecModel(*t, codec); !st)
            return makeError(st.error());
        return extendTrace(*t, frames);
    }
    return makeError(fmt::format("unknown bench '{}': expected one of {} (or --trace FILE)", name,
                                 suiteBenchNamesList()));
}

}  // namespace qvr
