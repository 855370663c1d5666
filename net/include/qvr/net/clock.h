// The time seam of the net part: the transport reads a Clock, tests drive a FakeClock, so link
// shaping and throughput estimation are deterministic under test (STYLE.md §4).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

namespace qvr::net {

class Clock {
public:
    virtual ~Clock() = default;
    virtual int64_t nowNs() const = 0;
};

// std::chrono::steady_clock: the one clock of a process's telemetry.
class SteadyClock final : public Clock {
public:
    int64_t nowNs() const override {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(
                   std::chrono::steady_clock::now().time_since_epoch())
            .count();
    }
    static const SteadyClock& instance() {
        static const SteadyClock clock;
        return clock;
    }
};

class FakeClock final : public Clock {
public:
    explicit FakeClock(int64_t start_ns = 0) : m_now_ns(start_ns) {}
    int64_t nowNs() const override { return m_now_ns.load(); }
    void advanceNs(int64_t dt_ns) { m_now_ns += dt_ns; }
    void setNs(int64_t now_ns) { m_now_ns = now_ns; }

private:
    std::atomic<int64_t> m_now_ns;
};

}  // namespace qvr::net
