// The machine an experiment runs on (host.h).
#include "qvr/experiment/host.h"

#include <ctime>
#include <fstream>

#include <fmt/format.h>

#include "qvr/runtime/affinity.h"

namespace qvr::experiment {

std::string cpuModel() {
    std::ifstream cpu("/proc/cpuinfo");
    for (std::string line; std::getline(cpu, line);) {
        const auto colon = line.find(':');
        if (line.rfind("model name", 0) == 0 && colon != std::string::npos &&
            colon + 2 <= line.size())
            return line.substr(colon + 2);
    }
    return "unknown CPU";
}

std::string machineDescription() {
    return fmt::format("{} × {}", runtime::onlineCores(), cpuModel());
}

double loadAverage1() {
    std::ifstream in("/proc/loadavg");
    double load = -1.0;
    in >> load;
    return load;
}

std::string utcNow() {
    const std::time_t t = std::time(nullptr);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
    return buf;
}

}  // namespace qvr::experiment
