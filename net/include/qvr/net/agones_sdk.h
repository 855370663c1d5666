// The lifecycle calls a game server makes to Agones' SDK sidecar, over the sidecar's REST
// gateway (agones.dev, "REST Game Server Client API"): Ready when the server takes headsets,
// Health while it serves, Shutdown when it ends — each an HTTP/1.1 POST of an empty JSON body
// to http://localhost:${AGONES_SDK_HTTP_PORT}/ready, /health or /shutdown. The sidecar answers
// only on the pod's loopback and asks for no authentication; a reply is read to at most
// kAgonesMaxReplyBytes.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "qvr/core/expected.h"

namespace qvr::net {

// The sidecar's default HTTP port, when AGONES_SDK_HTTP_PORT is not set.
inline constexpr uint16_t kAgonesDefaultHttpPort = 9358;
inline constexpr size_t kAgonesMaxReplyBytes = 16 * 1024;

// AGONES_SDK_HTTP_PORT's value (nullptr or empty: the default port) as a port in 1..65535.
Expected<uint16_t> agonesHttpPort(const char* env_value);

struct AgonesSdkOptions {
    std::string host = "127.0.0.1";
    uint16_t port = kAgonesDefaultHttpPort;
    int timeout_ms = 2000;     // one request: connect, send, the whole reply
    int ready_attempts = 20;   // the sidecar may start after the server (Agones' advice)
    int retry_delay_ms = 500;  // between Ready's attempts
};

// One call's route and outcome, counted.
struct AgonesSdkCounters {
    std::atomic<int> ready_sent{0}, health_sent{0}, shutdown_sent{0}, failed{0};
};

class AgonesSdk {
public:
    explicit AgonesSdk(AgonesSdkOptions options);
    // POST /ready, retried up to ready_attempts times.
    Status ready();
    // POST /health, once.
    Status health();
    // POST /shutdown, once.
    Status shutdown();
    const AgonesSdkCounters& counters() const { return m_counters; }
    const AgonesSdkOptions& options() const { return m_options; }

private:
    Status post(const std::string& route);
    AgonesSdkOptions m_options;
    AgonesSdkCounters m_counters;
};

// Sends Health every period on its own thread, from construction until destruction (or
// stop()), so the sidecar keeps the server Healthy while it serves. A failed ping is counted
// and the next one tried: Agones marks the server Unhealthy after its own failure threshold.
class AgonesHealthPinger {
public:
    AgonesHealthPinger(AgonesSdk& sdk, int period_ms);
    ~AgonesHealthPinger();
    AgonesHealthPinger(const AgonesHealthPinger&) = delete;
    AgonesHealthPinger& operator=(const AgonesHealthPinger&) = delete;
    void stop();

private:
    AgonesSdk& m_sdk;
    int m_period_ms;
    std::mutex m_mutex;
    std::condition_variable m_wake;
    bool m_stop = false;
    std::thread m_thread;
};

}  // namespace qvr::net
