// HOST:PORT as a user types it, and literal bind addresses.
#include <gtest/gtest.h>

#include "qvr/net/host_port.h"

namespace qvr {
namespace {

TEST(HostPort, AcceptsIpv4AndBracketedIpv6) {
    std::string host, error;
    uint16_t port = 0;
    ASSERT_TRUE(parseHostPort("127.0.0.1:7400", host, port, error)) << error;
    EXPECT_EQ(host, "127.0.0.1");
    EXPECT_EQ(port, 7400);
    ASSERT_TRUE(parseHostPort("[::1]:65535", host, port, error)) << error;
    EXPECT_EQ(host, "::1");
    EXPECT_EQ(port, 65535);
}

TEST(HostPort, RefusesBadPortsAndHostsWithAReason) {
    std::string host, error;
    uint16_t port = 0;
    for (const char* bad : {"127.0.0.1", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:-1", ":7400",
                            "::1:7400", "[nope]:7400", "999.1.1.1:7400"}) {
        error.clear();
        EXPECT_FALSE(parseHostPort(bad, host, port, error)) << bad;
        EXPECT_FALSE(error.empty()) << bad;
    }
}

TEST(HostPort, BindAddressesAreLiterals) {
    EXPECT_TRUE(isIpAddress("0.0.0.0"));
    EXPECT_TRUE(isIpAddress("::"));
    EXPECT_FALSE(isIpAddress("localhost"));
    EXPECT_FALSE(isIpAddress(""));
}

}  // namespace
}  // namespace qvr
