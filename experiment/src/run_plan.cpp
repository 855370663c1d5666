#include "qvr/experiment/run_plan.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>

namespace qvr::experiment {

namespace fs = std::filesystem;

CalibrateOptions runCalibrateOptions(const RunOptions& plan) {
    CalibrateOptions co;
    co.scene = plan.scene;  // the bits law and the render costs are the scene's
    co.profile = plan.profile;
    co.codec = plan.codec;
    co.lod_px = plan.lod_px;
    co.core = 0;
    co.verbose = false;
    return co;
}

namespace {

Expected<CalibrationChoice> calibrationFromFile(const std::string& path) {
    auto hw = loadHardwareConfig(path, 500.0);
    if (!hw)
        return makeError("--hardware: " + hw.error());
    if (!hw->runtime_pipeline)
        return makeError("--hardware: " + path +
                         " is not a calibration (no [runtime] pipeline = \"runtime\"; "
                         "qvr calibrate --out FILE writes one)");
    CalibrationChoice c;
    c.hardware = *hw;
    c.source = "file";
    c.path = path;
    c.note = "calibration from " + path;
    return c;
}

// Measures this machine now and keeps the result in the cache.
Expected<CalibrationChoice> calibrateNow(const RunOptions& plan, const CalibrateOptions& co,
                                         const std::string& cache) {
    // In its own thread pinned to the headset's core, so this thread's mask (inherited by the
    // server process) stays whole.
    Expected<Calibration> cal = makeError("not run");
    std::thread t([&] { cal = runCalibration(co); });
    t.join();
    if (!cal)
        return makeError("calibration: " + cal.error());
    cal->command = "qvr run (calibrating first: qvr calibrate --scene " + plan.scene +
                   " --profile " + plan.profile + ")";
    std::error_code ec;
    fs::create_directories(fs::path(cache).parent_path(), ec);
    if (std::ofstream f(cache); f)
        f << cal->toToml();
    auto hw = parseHardwareConfig(cal->toToml(), "calibration", 500.0);
    if (!hw)
        return makeError("calibration: " + hw.error());
    CalibrationChoice c;
    c.hardware = *hw;
    c.source = "measured";
    c.path = cache;
    c.seconds = cal->seconds;
    c.note = fmt::format("calibrated now, before the run, in {:.1f} s (saved as {})", cal->seconds,
                         cache);
    return c;
}

}  // namespace

Expected<CalibrationChoice> chooseCalibration(const RunOptions& plan) {
    if (!plan.hardware.empty())
        return calibrationFromFile(plan.hardware);
    const CalibrateOptions co = runCalibrateOptions(plan);
    const std::string cache = calibrationCachePath(co);
    if (!plan.recalibrate && fs::exists(cache)) {
        auto hw = loadHardwareConfig(cache, 500.0);
        if (hw) {
            CalibrationChoice c;
            c.hardware = *hw;
            c.source = "cached";
            c.path = cache;
            c.note = "this machine's cached calibration " + cache +
                     " (qvr run --recalibrate to measure again)";
            return c;
        }
        std::fprintf(stderr, "qvr run: ignoring the cached calibration: %s\n", hw.error().c_str());
    }
    return calibrateNow(plan, co, cache);
}

}  // namespace qvr::experiment
