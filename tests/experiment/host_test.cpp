#include "qvr/experiment/host.h"

#include <regex>

#include <gtest/gtest.h>

namespace qvr::experiment {

TEST(Host, DescribesCoresAndModel) {
    const std::string d = machineDescription();
    EXPECT_TRUE(std::regex_match(d, std::regex(R"(\d+ × .+)"))) << d;
    EXPECT_NE(d.find(cpuModel()), std::string::npos);
}

TEST(Host, UtcNowIsAMinuteStamp) {
    EXPECT_TRUE(std::regex_match(utcNow(), std::regex(R"(\d{4}-\d\d-\d\d \d\d:\d\d UTC)")))
        << utcNow();
}

TEST(Host, LoadAverageIsReadOnLinux) {
    EXPECT_GE(loadAverage1(), 0.0);
}

}  // namespace qvr::experiment
