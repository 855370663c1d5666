#include "qvr/core/cpu_cores.h"

#include <sched.h>
#include <unistd.h>

#include <fmt/format.h>

namespace qvr {

std::vector<int> allowedCores() {
    std::vector<int> cores;
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) == 0)
        for (int c = 0; c < CPU_SETSIZE; ++c)
            if (CPU_ISSET(c, &set))
                cores.push_back(c);
    if (cores.empty())  // the mask could not be read: every online core
        for (long c = 0; c < sysconf(_SC_NPROCESSORS_ONLN); ++c)
            cores.push_back(static_cast<int>(c));
    return cores;
}

std::string describeCores(const std::vector<int>& cores) {
    std::string out;
    for (size_t i = 0; i < cores.size();) {
        size_t j = i;
        while (j + 1 < cores.size() && cores[j + 1] == cores[j] + 1)
            ++j;
        if (!out.empty())
            out += ',';
        out += j == i ? std::to_string(cores[i]) : fmt::format("{}-{}", cores[i], cores[j]);
        i = j + 1;
    }
    return out;
}

}  // namespace qvr
