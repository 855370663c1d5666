// `qvr validate`: the simulator's correlation sheet. Calibrates each scene (qvr calibrate, apart
// from every run: by default anew for each repetition, before its runs), then runs `qvr run` for
// each condition — links × scenes × pipeline depths, every design, a few repetitions — each
// predicted with its repetition's calibration, and
// prints one table of the signed prediction errors with their mean absolute and worst values.
// docs/MODEL.md §8.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "qvr/experiment/calibration.h"
#include "commands.h"
#include "options.h"
#include "qvr/experiment/host.h"
#include "qvr/runtime/server_process.h"
#include "qvr/sim/hardware.h"

namespace qvr::cli {

using namespace qvr::experiment;  // the experiment part this command drives

namespace {

namespace fs = std::filesystem;

struct ValidateOptions {
    std::string designs = "local,remote,ffr,sw,qvr";
    std::string links;  // default: wifi,lte,5g and the ATT Mahimahi trace when found
    std::string scenes = "builtin:room,openarena:oa_dm5";
    std::string depths = "1,2";
    int frames = 40;
    int reps = 1;
    // A run taken again when its speed probes say the machine was not steady over it.
    int retakes = 1;
    std::string hardware;  // a calibration to use instead of calibrating (one scene only)
    std::string calibrate = "per-rep";  // or "once": when each scene is calibrated
    std::string profile = "default";
    std::string out = "qvr-validate";
    bool dry_run = false;
};

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t comma = s.find(',', start);
        const std::string item =
            s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (!item.empty())
            out.push_back(item);
        if (comma == std::string::npos)
            break;
        start = comma + 1;
    }
    return out;
}

// A Mahimahi trace of the shared data: searched upward from the working directory and the
// executable's folder for shared/data/network or data/network.
std::string findMahimahiTrace(const std::string& file) {
    std::error_code ec;
    std::vector<fs::path> starts = {fs::current_path(ec)};
    if (auto exe = runtime::selfExecutable(); exe)
        starts.push_back(fs::path(*exe).parent_path());
    for (const fs::path& start : starts)
        for (fs::path p = start; !p.empty(); p = p.parent_path()) {
            for (const fs::path& c :
                 {p / "shared" / "data" / "network" / file, p / "data" / "network" / file})
                if (fs::exists(c, ec))
                    return c.string();
            if (p == p.parent_path())
                break;
        }
    return {};
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string safeName(const std::string& s) {
    std::string out;
    for (char c : s)
        out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-') ? c : '_';
    return out.size() > 40 ? out.substr(out.size() - 40) : out;
}

// SIGINT/SIGTERM stop the sheet: the signal is passed to the calibration or run under way (a
// run then ends its design and writes what it measured), no further one starts, and the sheet
// of the runs that ended is written; the exit status is 130. (With std::system the parent
// ignored SIGINT while a run went on, so Ctrl-C ended one run and the next one started; a
// SIGTERM left the run behind, orphaned.)
std::atomic<pid_t> g_validate_child{0};
volatile std::sig_atomic_t g_validate_stop = 0;
static_assert(std::atomic<pid_t>::is_always_lock_free);

void onValidateSignal(int sig) {
    g_validate_stop = sig;
    if (const pid_t c = g_validate_child.load(); c > 0)
        ::kill(c, sig);
}

// Runs `cmd` through /bin/sh (exec'd, so the shell's child is the command itself and the signal
// above reaches it), stdin from /dev/null. The exit status, 128 + N for signal N, -1 when it
// could not start.
int runCommand(const std::string& cmd) {
    const std::string line = "exec " + cmd + " < /dev/null";
    const pid_t pid = ::fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        ::execl("/bin/sh", "sh", "-c", line.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    g_validate_child.store(pid);
    if (g_validate_stop != 0)  // a signal between the fork and the store
        ::kill(pid, g_validate_stop);
    int st = 0;
    pid_t w;
    do {
        w = ::waitpid(pid, &st, 0);
    } while (w < 0 && errno == EINTR);
    g_validate_child.store(0);
    if (w < 0)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
}

struct Row {
    std::string scene, link, design;
    int depth = 0;
    std::vector<double> fps_err, mtp_err, bytes_err, e1_err_abs, fps_meas, fps_pred;
    // Each side's own cost against the model's (docs/MODEL.md §8, "Stage errors"): a host that
    // changed speed since the calibration shows here as well as in the FPS.
    std::vector<double> headset_err, server_err;
    // The FPS error with each design's costs at its speed probes' speed (qvr run's
    // predicted_at_probe_speed).
    std::vector<double> fps_err_probe_speed;
};

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

// How far the machine moved from steady over a run, in percent, by the run's own speed probes
// (summary.json calibration.speed_reference): the larger of the probes' spread over the run and
// their mean's distance from the calibration's reference, either side. NaN when the run took
// no probes (a calibration without a reference).
double runDisturbancePct(const nlohmann::json& summary) {
    const nlohmann::json sp = summary.value("calibration", nlohmann::json::object())
                                  .value("speed_reference", nlohmann::json::object());
    const nlohmann::json spread = sp.value("run_spread_pct", nlohmann::json::object());
    const nlohmann::json over = sp.value("run_over_reference", nlohmann::json());
    if (!over.is_object())  // no probes were taken: run_spread_pct is 0 then, not a reading
        return NAN;
    double d = NAN;
    for (const char* side : {"headset", "server"}) {
        if (spread.contains(side) && spread[side].is_number())
            d = std::fmax(d, spread[side].get<double>());
        if (over.contains(side) && over[side].is_number())
            d = std::fmax(d, 100.0 * std::fabs(over[side].get<double>() - 1.0));
    }
    return d;
}

// The largest spread of a calibration's speed probes (its JSON copy's speed_reference.probes),
// either side, in percent; NaN without probes or without the file.
double calibrationSpreadPct(const std::string& json_path) {
    std::ifstream f(json_path);
    const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
    if (j.is_discarded() || !j.is_object())
        return NAN;
    const nlohmann::json probes = j.value("speed_reference", nlohmann::json::object())
                                      .value("probes", nlohmann::json::array());
    if (!probes.is_array() || probes.size() < 2)
        return NAN;
    std::vector<SpeedSample> samples;
    for (const nlohmann::json& p : probes) {
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

// Steady by the speed probes: within 10%, or no probe taken (NaN: nothing to tell, so a take
// without probes is never taken again).
bool steadyByProbes(double pct) {
    return !std::isfinite(pct) || pct <= kUnsteadySpeedPct;
}

// What follows a take's "done": how far its probes moved, and whether it is taken again.
std::string takeNote(double pct, bool more_takes) {
    if (!std::isfinite(pct))
        return {};
    return fmt::format(" (speed moved {:.0f}%{})", pct,
                       steadyByProbes(pct) ? ""
                       : more_takes        ? ": unsteady, again"
                                           : ": unsteady");
}

std::string cell(double v, const char* f) {
    return std::isfinite(v) ? fmt::format(fmt::runtime(f), v) : std::string("—");
}

int runValidate(const ValidateOptions& o) {
    const auto exe = runtime::selfExecutable();
    if (!exe) {
        std::fprintf(stderr, "qvr validate: %s\n", exe.error().c_str());
        return 1;
    }
    g_validate_stop = 0;
    std::signal(SIGINT, onValidateSignal);
    std::signal(SIGTERM, onValidateSignal);
    std::vector<std::string> links = splitList(o.links);
    if (o.links.empty()) {
        links = {"wifi", "lte", "5g"};
        const std::string att = findMahimahiTrace("ATT-LTE-driving-2016.down");
        if (!att.empty())
            links.push_back("trace:" + att);
        else
            std::fprintf(stderr,
                         "qvr validate: no ATT-LTE-driving-2016.down found (shared/data/network); "
                         "validating without a Mahimahi trace\n");
    }
    const std::vector<std::string> scenes = splitList(o.scenes);
    std::vector<int> depths;
    for (const std::string& d : splitList(o.depths)) {
        if (d != "1" && d != "2") {
            std::fprintf(stderr, "qvr validate: --depths takes 1 and/or 2, got '%s'\n", d.c_str());
            return 2;
        }
        depths.push_back(d == "1" ? 1 : 2);
    }
    if (links.empty() || scenes.empty() || depths.empty() || splitList(o.designs).empty()) {
        std::fprintf(stderr, "qvr validate: empty --links, --scenes, --depths or --designs\n");
        return 2;
    }
    if (!o.hardware.empty() && scenes.size() != 1) {
        std::fprintf(stderr,
                     "qvr validate: --hardware is one scene's calibration; give one "
                     "--scenes\n");
        return 2;
    }
    std::string hardware;  // absolute, as the runs are given it
    if (!o.hardware.empty()) {
        auto hw = loadHardwareConfig(o.hardware, 500.0);
        if (!hw) {
            std::fprintf(stderr, "qvr validate: --hardware: %s\n", hw.error().c_str());
            return 2;
        }
        if (!hw->runtime_pipeline) {
            std::fprintf(stderr,
                         "qvr validate: --hardware: %s is not a calibration (qvr calibrate --out "
                         "FILE writes one)\n",
                         o.hardware.c_str());
            return 2;
        }
        std::error_code aec;
        hardware = fs::absolute(o.hardware, aec).string();
    }
    std::error_code ec;
    fs::create_directories(o.out, ec);
    if (ec) {
        std::fprintf(stderr, "qvr validate: cannot create '%s': %s\n", o.out.c_str(),
                     ec.message().c_str());
        return 1;
    }
    const fs::path out(o.out);
    const auto t0 = std::chrono::steady_clock::now();
    const int conditions = int(links.size() * scenes.size() * depths.size());
    fmt::print(
        "qvr validate: {} conditions ({} links × {} scenes × {} depths) × {} repetition(s), "
        "designs {}, {} frames each; {}\n",
        conditions, links.size(), scenes.size(), depths.size(), o.reps, o.designs, o.frames,
        experiment::machineDescription());

    // 1. The calibrations: by default each repetition calibrates each scene anew, just before
    // that repetition's runs of the scene, and predicts them with it — so the repetitions repeat
    // the whole measurement (calibrate, predict, run), not the runs alone. On a host whose speed
    // moves from one minute to the next (docs/MODEL.md §8), one calibration per scene is one
    // sample of that speed, and every run of the scene inherits its error; with one per
    // repetition the error of each enters its own repetition, and the spread over repetitions
    // states it. `--calibrate once` keeps the single calibration per scene, before any run.
    std::map<std::string, std::string> calibration;  // key: scene|rep (rep 0 for `once`)
    std::vector<double> calibration_spread;          // per calibration: the chosen take's probes
    nlohmann::json calibrations_json = nlohmann::json::array();
    const bool per_rep = o.calibrate == "per-rep" && hardware.empty();
    auto calibrationKey = [&](const std::string& scene, int rep) {
        return fmt::format("{}|{}", scene, per_rep ? rep : 0);
    };
    // Calibrates `scene` for repetition `rep` (0-based); 0 on success, else the exit status.
    auto calibrate = [&](const std::string& scene, int rep) -> int {
        const std::string key = calibrationKey(scene, rep);
        if (!hardware.empty()) {
            fmt::print("  using the calibration {} (--hardware) on {}\n", hardware, scene);
            calibration[key] = hardware;
            return 0;
        }
        // A calibration whose own three speed probes are over 10% apart was taken on an unsteady
        // machine: it is taken again like a run, the steadiest counts.
        double best_spread = INFINITY;
        int best_take = 0;
        for (int take = 0; take <= o.retakes; ++take) {
            const std::string file =
                (out / fmt::format("calibration-{}{}{}.toml", safeName(scene),
                                   rep == 0 ? "" : fmt::format("-r{}", rep + 1),
                                   take == 0 ? "" : fmt::format("-t{}", take + 1)))
                    .string();
            const std::string cmd =
                fmt::format("{} calibrate --scene {} --profile {} --out {} > {} 2>&1",
                            shellQuote(*exe), shellQuote(scene), shellQuote(o.profile),
                            shellQuote(file), shellQuote(file + ".log"));
            fmt::print("  calibrating on {}{}{} ...", scene,
                       per_rep ? fmt::format(" for rep {}", rep + 1) : "",
                       take == 0 ? "" : fmt::format(" (take {})", take + 1));
            std::fflush(stdout);
            if (o.dry_run) {
                fmt::print("\n    {}\n", cmd);
                calibration[key] = file;
                return 0;
            }
            const int rc = runCommand(cmd);
            if (g_validate_stop != 0) {
                std::fprintf(stderr, "\nqvr validate: stopped (signal %d) while calibrating\n",
                             int(g_validate_stop));
                return 130;
            }
            if (rc != 0) {
                std::fprintf(stderr,
                             "\nqvr validate: calibration on %s failed (exit %d), see %s.log\n",
                             scene.c_str(), rc, file.c_str());
                return rc == 2 ? 2 : 1;
            }
            const double sp = calibrationSpreadPct(file + ".json");
            if (!(sp >= best_spread)) {  // NaN (no probes) counts as steady
                calibration[key] = file;
                best_spread = sp;
                best_take = take;
            }
            fmt::print(" done{}\n", takeNote(sp, take < o.retakes));
            if (steadyByProbes(sp))
                break;
        }
        if (best_take > 0)
            fmt::print("  on {} the runs use {}, the steadiest\n", scene, calibration[key]);
        calibration_spread.push_back(best_spread);
        calibrations_json.push_back({{"scene", scene},
                                     {"rep", per_rep ? rep + 1 : 0},
                                     {"file", calibration[key]},
                                     {"probe_spread_pct", best_spread}});
        return 0;
    };
    if (!per_rep)
        for (const std::string& scene : scenes)
            if (const int rc = calibrate(scene, 0); rc != 0)
                return rc;

    // 2. The runs. A run whose speed probes moved over 10% across it, or whose mean was over
    // 10% off the calibration's reference, was not measured on a steady machine: it is taken
    // again, up to --retakes times, and the steadiest take counts (chosen by the probes alone,
    // never by the prediction's error). The first takes' sheet is printed beside it.
    // key: scene|link|depth|design. rows_steady: the counted runs whose probes stayed within 10%.
    std::map<std::string, Row> rows, rows_first, rows_steady;
    size_t counted_steady = 0;
    std::vector<std::string> order;
    int failures = 0, retaken = 0, still_unsteady = 0;
    size_t counted = 0;                    // runs on the sheet (one take each)
    std::vector<double> run_speed_spread;  // per counted run: the probes' largest spread, percent
    std::vector<double> run_disturbance;   // per counted run: runDisturbancePct
    auto addRun = [](std::map<std::string, Row>& into, std::vector<std::string>* keys,
                     const nlohmann::json& j, const std::string& scene, const std::string& link,
                     int depth) {
        for (auto it = j["designs"].begin(); it != j["designs"].end(); ++it) {
            const nlohmann::json& d = it.value();
            if (!d.contains("prediction_error_pct"))
                continue;
            const std::string key = fmt::format("{}|{}|{}|{}", scene, link, depth, it.key());
            if (!into.count(key)) {
                if (keys)
                    keys->push_back(key);
                Row row;
                row.scene = scene;
                row.link = link;
                row.design = it.key();
                row.depth = depth;
                into[key] = std::move(row);
            }
            Row& r = into[key];
            const nlohmann::json& e = d["prediction_error_pct"];
            auto num = [](const nlohmann::json& v) {
                return v.is_number() ? v.get<double>() : NAN;
            };
            r.fps_err.push_back(num(e["fps_mean"]));
            r.mtp_err.push_back(num(e["mtp_ms_mean"]));
            r.bytes_err.push_back(num(e["bytes_per_frame_mean"]));
            r.e1_err_abs.push_back(num(d["prediction_error_abs"]["e1_deg_mean"]));
            r.fps_meas.push_back(num(d["fps_mean"]));
            r.fps_pred.push_back(num(d["predicted"]["fps_mean"]));
            r.headset_err.push_back(num(e.value("headset_busy_ms_mean", nlohmann::json())));
            r.server_err.push_back(num(e.value("server_busy_ms_mean", nlohmann::json())));
            if (d.contains("prediction_error_pct_at_probe_speed"))
                r.fps_err_probe_speed.push_back(
                    num(d["prediction_error_pct_at_probe_speed"]["fps_mean"]));
        }
    };
    bool stopped = false;
    for (int rep = 0; rep < o.reps && !stopped; ++rep)
        for (const std::string& scene : scenes) {
            // A repetition's calibration stopped by a signal ends the sheet as a run's stop does
            // (the runs that ended are written); one that failed leaves this scene's runs of this
            // repetition without a prediction: counted as a failure, the sheet goes on (bad input,
            // exit 2 from calibrate, ends it with 2).
            if (per_rep)
                if (const int rc = calibrate(scene, rep); rc != 0) {
                    if (g_validate_stop != 0) {
                        stopped = true;
                        break;
                    }
                    if (rc == 2)  // bad input (a scene or profile calibrate refuses)
                        return 2;
                    ++failures;
                    continue;
                }
            for (const std::string& link : links)
                for (int depth : depths) {
                    if (stopped)
                        break;
                    nlohmann::json first, best;
                    double best_disturbance = INFINITY;
                    for (int take = 0; take <= o.retakes; ++take) {
                        const fs::path dir =
                            out / fmt::format("{}_{}_d{}_r{}{}", safeName(scene), safeName(link),
                                              depth, rep + 1,
                                              take == 0 ? "" : fmt::format("_t{}", take + 1));
                        const std::string cmd = fmt::format(
                            "{} run --scene {} --net {} --pipeline {} --designs {} --frames {} "
                            "--profile {} --hardware {} --no-video --out {} > {} 2>&1",
                            shellQuote(*exe), shellQuote(scene), shellQuote(link), depth,
                            shellQuote(o.designs), o.frames, shellQuote(o.profile),
                            shellQuote(calibration[calibrationKey(scene, rep)]),
                            shellQuote(dir.string()), shellQuote((dir.string()) + ".log"));
                        fmt::print("  {} | {} | depth {} | rep {}{} ...", scene, link, depth,
                                   rep + 1, take == 0 ? "" : fmt::format(" take {}", take + 1));
                        std::fflush(stdout);
                        if (o.dry_run) {
                            fmt::print("\n    {}\n", cmd);
                            break;
                        }
                        const int rc = runCommand(cmd);
                        if (g_validate_stop != 0) {  // this run was cut short: not counted
                            fmt::print(" stopped\n");
                            stopped = true;
                            break;
                        }
                        nlohmann::json j;
                        if (rc == 0) {
                            std::ifstream f(dir / "summary.json");
                            j = nlohmann::json::parse(f, nullptr, false);
                        }
                        if (rc != 0 || j.is_discarded() || !j.contains("designs")) {
                            ++failures;
                            fmt::print(" failed (exit {}), see {}.log\n", rc, dir.string());
                            break;
                        }
                        const double dist = runDisturbancePct(j);
                        if (take == 0)
                            first = j;
                        else
                            ++retaken;
                        if (!(dist >= best_disturbance)) {  // NaN (no probes) counts as steady
                            best = j;
                            best_disturbance = dist;
                        }
                        fmt::print(" done{}\n", takeNote(dist, take < o.retakes));
                        if (steadyByProbes(dist))
                            break;
                    }
                    if (best.is_null())
                        continue;
                    if (!steadyByProbes(best_disturbance))
                        ++still_unsteady;
                    {
                        const nlohmann::json spread_pct =
                            best["calibration"]
                                .value("speed_reference", nlohmann::json::object())
                                .value("run_spread_pct", nlohmann::json::object());
                        const double h = spread_pct.value("headset", NAN),
                                     sv = spread_pct.value("server", NAN);
                        if (std::isfinite(h) && std::isfinite(sv) &&
                            std::isfinite(best_disturbance))  // 0 when no probe was taken
                            run_speed_spread.push_back(std::max(h, sv));
                        if (std::isfinite(best_disturbance))
                            run_disturbance.push_back(best_disturbance);
                    }
                    addRun(rows, &order, best, scene, link, depth);
                    ++counted;
                    addRun(rows_first, nullptr, first, scene, link, depth);
                    // NaN (no probes): not judged, so not in the steady runs' sheet either.
                    if (best_disturbance <= kUnsteadySpeedPct) {
                        addRun(rows_steady, nullptr, best, scene, link, depth);
                        ++counted_steady;
                    }
                }
        }
    if (o.dry_run)
        return 0;

    // 3. The sheet.
    std::string md = fmt::format(
        "| scene | link | depth | design | FPS measured | FPS predicted | FPS error | MTP error | "
        "bytes error | e1 error | FPS spread over reps | headset cost error | server cost error "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    std::vector<double> abs_fps, abs_mtp, abs_bytes, abs_e1, abs_fps_probe_speed;
    nlohmann::json rows_json = nlohmann::json::array();
    for (const std::string& key : order) {
        const Row& r = rows[key];
        const double fe = mean(r.fps_err), me = mean(r.mtp_err), be = mean(r.bytes_err),
                     ee = mean(r.e1_err_abs);
        if (std::isfinite(fe))
            abs_fps.push_back(std::fabs(fe));
        if (std::isfinite(me))
            abs_mtp.push_back(std::fabs(me));
        if (std::isfinite(be))
            abs_bytes.push_back(std::fabs(be));
        if (std::isfinite(ee))
            abs_e1.push_back(std::fabs(ee));
        if (const double fc = mean(r.fps_err_probe_speed); std::isfinite(fc))
            abs_fps_probe_speed.push_back(std::fabs(fc));
        const std::string link_label =
            r.link.rfind("trace:", 0) == 0
                ? "trace:" + fs::path(r.link.substr(6)).filename().string()
                : r.link;
        md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                          r.scene, link_label, r.depth, r.design, cell(mean(r.fps_meas), "{:.1f}"),
                          cell(mean(r.fps_pred), "{:.1f}"), cell(fe, "{:+.1f}%"),
                          cell(me, "{:+.1f}%"), cell(be, "{:+.1f}%"), cell(ee, "{:+.1f}°"),
                          cell(spread(r.fps_meas), "{:.1f}"), cell(mean(r.headset_err), "{:+.1f}%"),
                          cell(mean(r.server_err), "{:+.1f}%"));
        rows_json.push_back({{"scene", r.scene},
                             {"link", r.link},
                             {"depth", r.depth},
                             {"design", r.design},
                             {"fps_measured", r.fps_meas},
                             {"fps_predicted", r.fps_pred},
                             {"fps_error_pct", r.fps_err},
                             {"mtp_error_pct", r.mtp_err},
                             {"bytes_error_pct", r.bytes_err},
                             {"e1_error_deg", r.e1_err_abs},
                             {"headset_cost_error_pct", r.headset_err},
                             {"server_cost_error_pct", r.server_err},
                             {"fps_error_pct_at_probe_speed", r.fps_err_probe_speed}});
    }
    auto worst = [](const std::vector<double>& v) {
        return v.empty() ? NAN : *std::max_element(v.begin(), v.end());
    };
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    md += fmt::format(
        "\nMean absolute error (worst): FPS {} ({}), MTP mean {} ({}), bytes/frame {} ({}), e1 {} "
        "({}) over {} design × condition cells; {} failed runs; {:.0f} s.\n",
        cell(mean(abs_fps), "{:.1f}%"), cell(worst(abs_fps), "{:.1f}%"),
        cell(mean(abs_mtp), "{:.1f}%"), cell(worst(abs_mtp), "{:.1f}%"),
        cell(mean(abs_bytes), "{:.1f}%"), cell(worst(abs_bytes), "{:.1f}%"),
        cell(mean(abs_e1), "{:.1f}°"), cell(worst(abs_e1), "{:.1f}°"), order.size(), failures,
        seconds);
    const size_t unsteady =
        static_cast<size_t>(std::count_if(run_speed_spread.begin(), run_speed_spread.end(),
                                          [](double x) { return x > kUnsteadySpeedPct; }));
    // The first takes alone, so that what the retakes changed is on the sheet.
    std::vector<double> abs_fps_first;
    for (const std::string& key : order)
        if (rows_first.count(key))
            if (const double fe = mean(rows_first[key].fps_err); std::isfinite(fe))
                abs_fps_first.push_back(std::fabs(fe));
    const size_t runs_counted = counted;
    // The steady runs alone: the model's error where the machine held its calibration's speed.
    std::vector<double> abs_fps_steady, abs_mtp_steady;
    for (const std::string& key : order)
        if (rows_steady.count(key)) {
            if (const double fe = mean(rows_steady[key].fps_err); std::isfinite(fe))
                abs_fps_steady.push_back(std::fabs(fe));
            if (const double me = mean(rows_steady[key].mtp_err); std::isfinite(me))
                abs_mtp_steady.push_back(std::fabs(me));
        }
    md += fmt::format(
        "The steady runs alone ({} of {}: speed probes within 10% across the run and of the "
        "calibration's reference; a run without probes is not judged): FPS {} ({}), MTP mean {} "
        "({}) over {} cells.\n",
        counted_steady, runs_counted, cell(mean(abs_fps_steady), "{:.1f}%"),
        cell(worst(abs_fps_steady), "{:.1f}%"), cell(mean(abs_mtp_steady), "{:.1f}%"),
        cell(worst(abs_mtp_steady), "{:.1f}%"), abs_fps_steady.size());
    md += fmt::format(
        "Runs taken again because their speed probes moved over 10% (across the run or from "
        "the calibration's reference): {} (up to {} per run); still unsteady after them: {} of "
        "{}. The first takes alone: FPS {} ({}).\n",
        retaken, o.retakes, still_unsteady, runs_counted, cell(mean(abs_fps_first), "{:.1f}%"),
        cell(worst(abs_fps_first), "{:.1f}%"));
    md += fmt::format(
        "With each design's costs at its speed probes' speed (predicted_at_probe_speed): FPS {} "
        "({}). The speed probes moved by a median {} over a run, over 10% in {} of {} runs.\n",
        cell(mean(abs_fps_probe_speed), "{:.1f}%"), cell(worst(abs_fps_probe_speed), "{:.1f}%"),
        [&] {
            if (run_speed_spread.empty())
                return std::string("—");
            std::vector<double> v = run_speed_spread;
            std::sort(v.begin(), v.end());
            return fmt::format("{:.1f}%", v[v.size() / 2]);
        }(),
        unsteady, run_speed_spread.size());
    if (stopped)
        md += fmt::format("Stopped by a signal: the sheet has the {} runs that ended of {}.\n",
                          runs_counted,
                          size_t(o.reps) * scenes.size() * links.size() * depths.size());
    fmt::print("\n{}", md);
    std::ofstream(out / "validation.md") << md;
    const nlohmann::json summary = {
        {"machine", experiment::machineDescription()},
        {"seconds", seconds},
        {"reps", o.reps},
        {"frames", o.frames},
        {"failed_runs", failures},
        {"fps_abs_error_pct_mean", mean(abs_fps)},
        {"fps_abs_error_pct_worst", worst(abs_fps)},
        {"mtp_abs_error_pct_mean", mean(abs_mtp)},
        {"mtp_abs_error_pct_worst", worst(abs_mtp)},
        {"bytes_abs_error_pct_mean", mean(abs_bytes)},
        {"bytes_abs_error_pct_worst", worst(abs_bytes)},
        {"e1_abs_error_deg_mean", mean(abs_e1)},
        {"e1_abs_error_deg_worst", worst(abs_e1)},
        {"fps_abs_error_pct_mean_at_probe_speed", mean(abs_fps_probe_speed)},
        {"fps_abs_error_pct_worst_at_probe_speed", worst(abs_fps_probe_speed)},
        {"run_speed_spread_pct", run_speed_spread},
        {"runs_unsteady", unsteady},
        {"retakes_max", o.retakes},
        {"calibrate", hardware.empty() ? o.calibrate : std::string("hardware")},
        {"calibrations", calibrations_json},
        {"calibration_probe_spread_pct", calibration_spread},
        {"runs_retaken", retaken},
        {"runs_unsteady_after_retakes", still_unsteady},
        {"run_disturbance_pct", run_disturbance},
        {"fps_abs_error_pct_mean_first_takes", mean(abs_fps_first)},
        {"runs_steady", counted_steady},
        {"fps_abs_error_pct_mean_steady_runs", mean(abs_fps_steady)},
        {"fps_abs_error_pct_worst_steady_runs", worst(abs_fps_steady)},
        {"mtp_abs_error_pct_mean_steady_runs", mean(abs_mtp_steady)},
        {"fps_abs_error_pct_worst_first_takes", worst(abs_fps_first)},
        {"rows", rows_json}};
    std::ofstream(out / "validation.json") << summary.dump(2) << "\n";
    fmt::print("  wrote {}/validation.md and validation.json\n", o.out);
    if (stopped) {
        std::fprintf(stderr, "qvr validate: stopped by signal %d\n", int(g_validate_stop));
        return 130;
    }
    return failures > 0 ? 1 : 0;
}

}  // namespace

static Registered registerValidate(CLI::App& app) {
    auto o = std::make_shared<ValidateOptions>();
    CLI::App* cmd = app.add_subcommand(
        "validate",
        "Calibrate, then run qvr run over links x scenes x pipeline depths and tabulate the "
        "calibrated simulator's prediction errors");
    cmd->add_option("--designs", o->designs, "Designs of every run")->capture_default_str();
    cmd->add_option("--links", o->links,
                    "Comma-separated qvr run --net specs (default: wifi,lte,5g and the ATT "
                    "Mahimahi trace of shared/data/network)");
    cmd->add_option("--scenes", o->scenes, "Comma-separated scenes")->capture_default_str();
    cmd->add_option("--depths", o->depths, "Frames in flight: 1, 2 or 1,2")->capture_default_str();
    addFramesOption(cmd, o->frames, 5, 100000, "Frames per design per run");
    cmd->add_option("--reps", o->reps, "Repetitions of every condition")
        ->check(CLI::Range(1, 20))
        ->capture_default_str();
    cmd->add_option("--retakes", o->retakes,
                    "Take a run again, up to this many times, when its speed probes moved over "
                    "10% across it or from the calibration's; the steadiest take counts")
        ->check(CLI::Range(0, 5))
        ->capture_default_str();
    cmd->add_option("--hardware", o->hardware,
                    "Use this calibration instead of calibrating (one scene)")
        ->check(readableFile());
    cmd->add_option("--calibrate", o->calibrate,
                    "per-rep: each repetition calibrates each scene anew before its runs; once: "
                    "one calibration per scene before any run")
        ->check(CLI::IsMember({"per-rep", "once"}))
        ->capture_default_str();
    addProfileOption(cmd, o->profile, ProfileNames::kRuntime);
    cmd->add_option("--out", o->out, "Output folder")->check(outputFolder())->capture_default_str();
    cmd->add_flag("--dry-run", o->dry_run, "Print the commands without running them");
    return {cmd, [o] { return runValidate(*o); }};
}

QVR_REGISTER_COMMAND(92, registerValidate);

}  // namespace qvr::cli
