// The other core's work for the co-running measurement, and the speed probe's process:
// `qvr corun-load` in a child process, pinned to its core. Internal to the experiment part.
#pragma once

#include <sys/types.h>
#include <memory>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/experiment/calibration.h"

namespace qvr::experiment {

// The child does one side's frames (SideMix, `mix` "server" or "headset") while told to be
// busy ("1" on its stdin, "0" to pause), or one speed probe per "p" (`mix` "probe"); it exits
// when its stdin closes.
class CoRunLoad {
public:
    // Started and ready (its scene loaded, a minute at most).
    static Expected<std::unique_ptr<CoRunLoad>> start(const CalibrateOptions& o, int core,
                                                      const std::string& mix);
    // Busy frames until told otherwise; the answer comes once the first frame under way after
    // "1" has finished, or at once after "0" (the current frame finishes first).
    Status setBusy(bool busy);
    // One speed probe in the child (mix "probe"): its line "headset_ms server_ms".
    Expected<SpeedSample> probe();
    // Its stdin closed; killed when it has not ended within 5 s.
    void stop();
    ~CoRunLoad();

private:
    CoRunLoad(pid_t pid, int in, int out) : m_pid(pid), m_in(in), m_out(out) {}
    // Two bytes to the child. One that died has closed its end: the write must fail with EPIPE,
    // not raise SIGPIPE and end the calibration, so SIGPIPE is blocked for this thread while it
    // writes, and one it raised is taken back.
    bool writeTwo(const char* bytes);
    pid_t m_pid;
    int m_in;
    int m_out;
};

}  // namespace qvr::experiment
