// The cores a process may run on, and their description in messages.
#include <gtest/gtest.h>

#include <thread>

#include "qvr/core/cpu_cores.h"

namespace qvr {
namespace {

TEST(CpuCores, DescribesRunsAsRanges) {
    EXPECT_EQ(describeCores({0, 1, 2, 5}), "0-2,5");
    EXPECT_EQ(describeCores({3}), "3");
    EXPECT_EQ(describeCores({0, 2, 4}), "0,2,4");
    EXPECT_EQ(describeCores({}), "");
}

TEST(CpuCores, ThisProcessMayRunOnSomeCore) {
    const std::vector<int> cores = allowedCores();
    ASSERT_FALSE(cores.empty());
    EXPECT_LE(cores.size(), std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace
}  // namespace qvr
