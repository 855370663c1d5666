// The cores this process may run on, and how a message names them.
#pragma once

#include <string>
#include <vector>

namespace qvr {

// The cores of the calling thread's affinity mask, ascending: pinning to any other fails. Under
// taskset, a cpuset or a container these are not 0…N−1. Never empty (every online core when the
// mask cannot be read).
std::vector<int> allowedCores();

// Ascending cores as ranges, e.g. {0, 1, 2, 5} → "0-2,5".
std::string describeCores(const std::vector<int>& cores);

}  // namespace qvr
