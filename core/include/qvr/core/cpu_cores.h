// The cores this process may run on, and how a message names them.
#pragma once

#include <string>
#include <vector>

namespace qvr {

// The cores of this process's affinity mask, ascending: pinning to any other fails.
std::vector<int> allowedCores();

// Ascending cores as ranges, e.g. {0, 1, 2, 5} → "0-2,5".
std::string describeCores(const std::vector<int>& cores);

}  // namespace qvr
