// The steady and fake clocks of the time seam.
#include "qvr/core/clock.h"

#include <chrono>
#include <thread>

namespace qvr {

int64_t SteadyClock::nowNs() const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

void SteadyClock::sleepUntilNs(int64_t deadline_ns) {
    const int64_t now_ns = nowNs();
    if (deadline_ns > now_ns)
        std::this_thread::sleep_for(std::chrono::nanoseconds(deadline_ns - now_ns));
}

SteadyClock& SteadyClock::instance() {
    static SteadyClock clock;
    return clock;
}

void FakeClock::sleepUntilNs(int64_t deadline_ns) {
    int64_t now_ns = m_now_ns.load();
    while (deadline_ns > now_ns && !m_now_ns.compare_exchange_weak(now_ns, deadline_ns)) {
    }
}

}  // namespace qvr
