// The Agones SDK client against a local stand-in for the SDK sidecar's REST routes (a loopback
// HTTP server written here, not Agones' own sidecar): which routes are posted, retries, and
// the faults — no sidecar, an error status, a reply that is not HTTP, a reply that never ends.
#include "qvr/net/agones_sdk.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace qvr::net {
namespace {

// A stand-in for the sidecar: accepts on 127.0.0.1, reads one request's head and body, records
// "METHOD PATH", answers with what `reply` gives for that request's index.
class SidecarStandIn {
public:
    using Reply = std::function<std::string(int index)>;
    explicit SidecarStandIn(Reply reply) : m_reply(std::move(reply)) {
        m_fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in addr{};
        addr.sin_family = AF_INET;
        addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        int one = 1;
        ::setsockopt(m_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        EXPECT_EQ(::bind(m_fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
        EXPECT_EQ(::listen(m_fd, 16), 0);
        socklen_t len = sizeof addr;
        ::getsockname(m_fd, reinterpret_cast<sockaddr*>(&addr), &len);
        m_port = ntohs(addr.sin_port);
        m_thread = std::thread([this] { serve(); });
    }
    ~SidecarStandIn() {
        m_stop = true;
        ::shutdown(m_fd, SHUT_RDWR);
        ::close(m_fd);
        m_thread.join();
    }
    uint16_t port() const { return m_port; }
    std::vector<std::string> requests() {
        std::lock_guard lock(m_mutex);
        return m_requests;
    }

private:
    void serve() {
        for (int index = 0; !m_stop; ++index) {
            const int c = ::accept(m_fd, nullptr, nullptr);
            if (c < 0)
                return;
            std::string head;
            char buf[1024];
            while (head.find("\r\n\r\n{}") == std::string::npos && head.size() < 8192) {
                const ssize_t n = ::recv(c, buf, sizeof buf, 0);
                if (n <= 0)
                    break;
                head.append(buf, static_cast<size_t>(n));
            }
            {
                std::lock_guard lock(m_mutex);
                m_requests.push_back(head.substr(0, head.find(" HTTP/1.1")));
            }
            const std::string reply = m_reply(index);
            if (reply != "hang")
                ::send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
            else
                std::this_thread::sleep_for(std::chrono::milliseconds(400));
            ::close(c);
        }
    }
    Reply m_reply;
    int m_fd = -1;
    uint16_t m_port = 0;
    std::atomic<bool> m_stop{false};
    std::mutex m_mutex;
    std::vector<std::string> m_requests;
    std::thread m_thread;
};

const std::string kOk =
    "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n"
    "Content-Length: 2\r\n\r\n{}";

AgonesSdkOptions optionsFor(uint16_t port) {
    AgonesSdkOptions o;
    o.port = port;
    o.timeout_ms = 300;
    o.ready_attempts = 3;
    o.retry_delay_ms = 10;
    return o;
}

TEST(AgonesSdk, PostsReadyHealthAndShutdownToTheirRoutes) {
    SidecarStandIn sidecar([](int) { return kOk; });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    ASSERT_TRUE(sdk.ready().ok());
    ASSERT_TRUE(sdk.health().ok());
    ASSERT_TRUE(sdk.shutdown().ok());
    EXPECT_EQ(sidecar.requests(),
              (std::vector<std::string>{"POST /ready", "POST /health", "POST /shutdown"}));
    EXPECT_EQ(sdk.counters().ready_sent, 1);
    EXPECT_EQ(sdk.counters().health_sent, 1);
    EXPECT_EQ(sdk.counters().shutdown_sent, 1);
    EXPECT_EQ(sdk.counters().failed, 0);
}

TEST(AgonesSdk, ReadyRetriesUntilTheSidecarAnswers) {
    SidecarStandIn sidecar([](int i) {
        return i < 2 ? std::string("HTTP/1.1 503 Service Unavailable\r\n\r\n") : kOk;
    });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    EXPECT_TRUE(sdk.ready().ok());
    EXPECT_EQ(sidecar.requests().size(), 3u);
    EXPECT_EQ(sdk.counters().failed, 2);
}

TEST(AgonesSdk, ReadyFailsAfterItsAttemptsWithTheStatus) {
    SidecarStandIn sidecar([](int) { return std::string("HTTP/1.1 500 Oops\r\n\r\n"); });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    const Status st = sdk.ready();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().find("HTTP status 500"), std::string::npos) << st.error();
    EXPECT_EQ(sidecar.requests().size(), 3u);
}

TEST(AgonesSdk, NoSidecarIsAnErrorNamingThePort) {
    uint16_t port = 0;
    {
        SidecarStandIn gone([](int) { return kOk; });
        port = gone.port();
    }
    AgonesSdk sdk(optionsFor(port));
    const Status st = sdk.health();
    ASSERT_FALSE(st.ok());
    const std::string where = fmt::format(":{}/health", port);
    EXPECT_NE(st.error().find(where), std::string::npos) << st.error();
}

TEST(AgonesSdk, AReplyThatIsNotHttpIsAnError) {
    SidecarStandIn sidecar([](int) { return std::string("SSH-2.0-OpenSSH\r\n"); });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    const Status st = sdk.health();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().find("not HTTP"), std::string::npos) << st.error();
}

TEST(AgonesSdk, AReplyThatNeverEndsTimesOut) {
    SidecarStandIn sidecar([](int) { return std::string("hang"); });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    const auto t0 = std::chrono::steady_clock::now();
    const Status st = sdk.shutdown();
    const double waited_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().find("no complete reply"), std::string::npos) << st.error();
    EXPECT_LT(waited_ms, 5000.0);  // bounded by the deadline, not by the peer
}

TEST(AgonesSdk, AHugeReplyIsReadOnlyToItsBound) {
    SidecarStandIn sidecar([](int) { return kOk + std::string(4 * kAgonesMaxReplyBytes, 'x'); });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    EXPECT_TRUE(sdk.health().ok());
}

TEST(AgonesSdk, HealthPingerPingsUntilStopped) {
    SidecarStandIn sidecar([](int) { return kOk; });
    AgonesSdk sdk(optionsFor(sidecar.port()));
    {
        AgonesHealthPinger pinger(sdk, 20);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
    const int sent = sdk.counters().health_sent;
    EXPECT_GE(sent, 3);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_EQ(sdk.counters().health_sent, sent);  // nothing after the pinger is gone
}

TEST(AgonesHttpPort, ReadsTheEnvironmentOrTheDefault) {
    EXPECT_EQ(*agonesHttpPort(nullptr), kAgonesDefaultHttpPort);
    EXPECT_EQ(*agonesHttpPort(""), kAgonesDefaultHttpPort);
    EXPECT_EQ(*agonesHttpPort("59358"), 59358);
    for (const char* bad : {"0", "65536", "99999", "abc", "12x", "-1", " 80", "123456"})
        EXPECT_FALSE(agonesHttpPort(bad).ok()) << bad;
}

}  // namespace
}  // namespace qvr::net
