// Display pacing: the vsync slot grid on the clock seam.
#include "qvr/runtime/pacing.h"

#include <algorithm>
#include <cmath>

#include "qvr/core/check.h"

namespace qvr::runtime {

VsyncPacer::VsyncPacer(Clock& clock, double refresh_hz)
    : m_clock(clock),
      m_period_ns(static_cast<int64_t>(std::llround(1e9 / std::max(refresh_hz, 1.0)))) {
    QVR_CHECK(m_period_ns > 0);
    reset();
}

void VsyncPacer::reset() {
    m_origin_ns = m_clock.nowNs();
    m_last_scanout_ns = -1;
}

int64_t VsyncPacer::slotAtOrAfter(int64_t t_ns) const {
    const int64_t since = std::max<int64_t>(t_ns - m_origin_ns, 0);
    int64_t k = (since + m_period_ns - 1) / m_period_ns;
    int64_t slot = m_origin_ns + k * m_period_ns;
    if (slot <= m_last_scanout_ns)
        slot = m_last_scanout_ns + m_period_ns;
    return slot;
}

int64_t VsyncPacer::waitForScanout(int64_t ready_ns) {
    const int64_t slot = slotAtOrAfter(ready_ns);
    m_clock.sleepUntilNs(slot);
    m_last_scanout_ns = slot;
    return slot;
}

int64_t VsyncPacer::queueForScanout(int64_t ready_ns) {
    const int64_t slot = slotAtOrAfter(ready_ns);
    m_clock.sleepUntilNs(slot - m_period_ns);
    m_last_scanout_ns = slot;
    return slot;
}

}  // namespace qvr::runtime
