// The display clock of the headset (paper Fig. 4: UCA runs once per refresh with the newest
// pose): the vsync pacer on the clock seam (qvr/core/clock.h).
#pragma once

#include <cstdint>

#include "qvr/core/clock.h"

namespace qvr::runtime {

// Vsync slots at origin + k·period. A frame whose composition finished at t is scanned out at
// the first slot at or after t; a frame that missed its slot waits for the next (no tearing).
class VsyncPacer {
public:
    VsyncPacer(Clock& clock, double refresh_hz);
    // Starts the slot grid at the clock's now.
    void reset();
    int64_t periodNs() const { return m_period_ns; }
    // The first slot at or after t_ns (strictly after the previous scan-out).
    int64_t slotAtOrAfter(int64_t t_ns) const;
    // Sleeps until the slot for a frame ready at ready_ns and returns that slot's time.
    int64_t waitForScanout(int64_t ready_ns);
    // Queues a frame ready at ready_ns for its slot and returns the slot's time, without
    // waiting for it: the display scans it out while the headset works on the next frame, as a
    // compositor with a two-image swapchain does. Sleeps only while an earlier frame still
    // holds the other image, i.e. until one period before the new slot.
    int64_t queueForScanout(int64_t ready_ns);
    int64_t lastScanoutNs() const { return m_last_scanout_ns; }

private:
    Clock& m_clock;
    int64_t m_period_ns;
    int64_t m_origin_ns = 0;
    int64_t m_last_scanout_ns = -1;
};

}  // namespace qvr::runtime
