// The machine an experiment runs on, as every report and result names it: CPU model, core
// count, load and the time of the measurement.
#pragma once

#include <string>

namespace qvr::experiment {

// The first "model name" of /proc/cpuinfo ("unknown CPU" when there is none).
std::string cpuModel();
// "N × MODEL": the online cores and the CPU model.
std::string machineDescription();
// The 1-minute load average (−1 when /proc/loadavg cannot be read).
double loadAverage1();
// Now, as "YYYY-MM-DD HH:MM UTC".
std::string utcNow();

}  // namespace qvr::experiment
