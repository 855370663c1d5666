// Agones' SDK sidecar over REST (agones_sdk.h): a blocking HTTP/1.1 POST with one deadline for
// the whole exchange, on its own io_context so it shares nothing with the media transport.
#include "qvr/net/agones_sdk.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <string_view>

#include <asio.hpp>

namespace qvr::net {

namespace {

using asio::ip::tcp;

// "HTTP/1.x 200 ..." → 200; −1 when the status line is not HTTP.
int httpStatus(std::string_view reply) {
    if (reply.size() < 12 || reply.substr(0, 7) != "HTTP/1.")
        return -1;
    const std::string_view code = reply.substr(9, 3);
    for (char c : code)
        if (c < '0' || c > '9')
            return -1;
    return (code[0] - '0') * 100 + (code[1] - '0') * 10 + (code[2] - '0');
}

// One POST of "{}" to host:port/route; the reply's first kAgonesMaxReplyBytes, or an error.
Expected<std::string> postOnce(const AgonesSdkOptions& o, const std::string& route) {
    asio::io_context io;
    tcp::socket socket(io);
    std::string error;
    std::string reply;
    const std::string request = "POST " + route + " HTTP/1.1\r\nHost: " + o.host + ":" +
                                std::to_string(o.port) +
                                "\r\nContent-Type: application/json\r\nContent-Length: 2\r\n"
                                "Connection: close\r\n\r\n{}";
    std::array<char, 4096> chunk{};
    std::function<void()> readMore = [&] {
        socket.async_read_some(asio::buffer(chunk), [&](std::error_code ec, size_t n) {
            reply.append(chunk.data(), std::min(n, kAgonesMaxReplyBytes - reply.size()));
            if (!ec && reply.size() < kAgonesMaxReplyBytes)
                readMore();
            else if (ec && ec != asio::error::eof)
                error = "reading the reply: " + ec.message();
        });
    };
    asio::error_code ec;
    const auto address = asio::ip::make_address(o.host, ec);
    if (ec)
        return makeError("'" + o.host + "' is not an IP address");
    socket.async_connect(tcp::endpoint(address, o.port), [&](std::error_code cec) {
        if (cec) {
            error = "connecting: " + cec.message();
            return;
        }
        asio::async_write(socket, asio::buffer(request), [&](std::error_code wec, size_t) {
            if (wec)
                error = "sending: " + wec.message();
            else
                readMore();
        });
    });
    io.run_for(std::chrono::milliseconds(o.timeout_ms));
    if (!io.stopped()) {
        socket.close(ec);
        io.run();  // let the cancelled handlers finish before the locals go
        error = "no complete reply within " + std::to_string(o.timeout_ms) + " ms";
    }
    if (!error.empty())
        return makeError(error);
    return reply;
}

}  // namespace

Expected<uint16_t> agonesHttpPort(const char* env_value) {
    if (env_value == nullptr || *env_value == '\0')
        return kAgonesDefaultHttpPort;
    const std::string_view text(env_value);
    if (text.size() > 5 || text.find_first_not_of("0123456789") != std::string_view::npos)
        return makeError("AGONES_SDK_HTTP_PORT must be a port number, got '" +
                         std::string(text.substr(0, 32)) + "'");
    const long port = std::strtol(env_value, nullptr, 10);
    if (port < 1 || port > 65535)
        return makeError("AGONES_SDK_HTTP_PORT must be in 1..65535, got " + std::string(text));
    return static_cast<uint16_t>(port);
}

AgonesSdk::AgonesSdk(AgonesSdkOptions options) : m_options(std::move(options)) {}

Status AgonesSdk::post(const std::string& route) {
    auto reply = postOnce(m_options, route);
    const std::string where =
        "Agones SDK sidecar at " + m_options.host + ":" + std::to_string(m_options.port) + route;
    if (!reply) {
        ++m_counters.failed;
        return makeError(where + ": " + reply.error());
    }
    const int status = httpStatus(*reply);
    if (status != 200) {
        ++m_counters.failed;
        return makeError(where + ": " +
                         (status < 0 ? std::string("the reply is not HTTP")
                                     : "HTTP status " + std::to_string(status)));
    }
    return Status::success();
}

Status AgonesSdk::ready() {
    Status last;
    for (int attempt = 0; attempt < std::max(1, m_options.ready_attempts); ++attempt) {
        if (attempt > 0)
            std::this_thread::sleep_for(std::chrono::milliseconds(m_options.retry_delay_ms));
        last = post("/ready");
        if (last.ok()) {
            ++m_counters.ready_sent;
            return last;
        }
    }
    return last;
}

Status AgonesSdk::health() {
    Status st = post("/health");
    if (st.ok())
        ++m_counters.health_sent;
    return st;
}

Status AgonesSdk::shutdown() {
    Status st = post("/shutdown");
    if (st.ok())
        ++m_counters.shutdown_sent;
    return st;
}

AgonesHealthPinger::AgonesHealthPinger(AgonesSdk& sdk, int period_ms)
    : m_sdk(sdk), m_period_ms(std::max(1, period_ms)) {
    m_thread = std::thread([this] {
        std::unique_lock lock(m_mutex);
        while (!m_stop) {
            lock.unlock();
            (void)m_sdk.health();
            lock.lock();
            m_wake.wait_for(lock, std::chrono::milliseconds(m_period_ms),
                            [this] { return m_stop; });
        }
    });
}

AgonesHealthPinger::~AgonesHealthPinger() {
    stop();
}

void AgonesHealthPinger::stop() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_wake.notify_all();
    if (m_thread.joinable())
        m_thread.join();
}

}  // namespace qvr::net
