// Where `qvr run` keeps the calibration of this machine and these options.
#include "qvr/experiment/calibration.h"

#include <cstdint>
#include <cstdlib>

#include <fmt/format.h>

#include "qvr/experiment/host.h"

namespace qvr::experiment {

std::string calibrationCacheKey(const CalibrateOptions& o) {
    // Raised whenever what the calibration measures, or how, changes: an older cache is not reused.
    constexpr int kCalibrationVersion = 19;
    const std::string text =
        fmt::format("v{}|{}|{}|{}|{}|{}|{}", kCalibrationVersion, machineDescription(), o.profile,
                    o.scene, o.codec, o.lod_px, o.core);
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return fmt::format("{:016x}", h);
}

std::string calibrationCachePath(const CalibrateOptions& o) {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    const std::string base = xdg && *xdg     ? std::string(xdg)
                             : home && *home ? std::string(home) + "/.cache"
                                             : std::string("/tmp");
    return base + "/qvr/calibration-" + calibrationCacheKey(o) + ".toml";
}

}  // namespace qvr::experiment
