// Sub-commands of `qvr bench`: each benchmark lives in its own cmd_bench_<name>.cpp, adds itself
// with QVR_REGISTER_BENCH, and cmd_bench.cpp mounts every registered one under `qvr bench`.
#pragma once

#include <vector>

#include "commands.h"

namespace qvr::cli {

struct BenchEntry {
    int order;
    RegisterFn fn;  // adds the benchmark's sub-command to the `bench` app
};

inline std::vector<BenchEntry>& benchRegistry() {
    static std::vector<BenchEntry> registry;
    return registry;
}

inline bool addBench(int order, RegisterFn fn) {
    benchRegistry().push_back({order, fn});
    return true;
}

}  // namespace qvr::cli

// Use inside namespace qvr::cli, after the register function.
#define QVR_REGISTER_BENCH(order, fn) \
    [[maybe_unused]] static const bool qvr_bench_registered_##fn = addBench(order, &fn)
