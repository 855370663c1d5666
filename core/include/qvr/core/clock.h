// The one time seam of a process: the transport, the headset's pacing and the render server
// read a Clock; production passes the steady clock, tests a FakeClock, so link shaping,
// throughput estimation and frame pacing are deterministic under test (STYLE.md §4).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

namespace qvr {

class Clock {
public:
    virtual ~Clock() = default;
    virtual int64_t nowNs() const = 0;
    // Returns at or after deadline_ns (at once if it has passed).
    virtual void sleepUntilNs(int64_t deadline_ns) = 0;
};

// std::chrono::steady_clock: the one clock of a process's telemetry.
class SteadyClock final : public Clock {
public:
    int64_t nowNs() const override;
    void sleepUntilNs(int64_t deadline_ns) override;
    static SteadyClock& instance();
};

// Time moves only when told to, or when someone sleeps: tests of timing are exact.
class FakeClock final : public Clock {
public:
    explicit FakeClock(int64_t start_ns = 0) : m_now_ns(start_ns) {}
    int64_t nowNs() const override { return m_now_ns.load(); }
    void sleepUntilNs(int64_t deadline_ns) override;
    void advanceNs(int64_t dt_ns) { m_now_ns += dt_ns; }
    void setNs(int64_t now_ns) { m_now_ns = now_ns; }

private:
    std::atomic<int64_t> m_now_ns;
};

// Times a piece of work (a render, an encode, a decode) on the steady clock, for the stats a
// part reports about itself; the seam above is for time that logic depends on.
class Stopwatch {
public:
    Stopwatch() : m_start(std::chrono::steady_clock::now()) {}
    double elapsedMs() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - m_start)
            .count();
    }

private:
    std::chrono::steady_clock::time_point m_start;
};

}  // namespace qvr
