// Pinning the headset and the server each to its own core (the headset's budget is not the
// server's). Threads a pinned thread creates (llvmpipe's rasterizers, x264) inherit the mask.
#pragma once

#include <string>
#include <vector>

#include "qvr/core/cpu_cores.h"  // allowedCores()
#include "qvr/core/expected.h"

namespace qvr::runtime {

int onlineCores();
// Pins the calling thread to `core` (0-based); an error when the core does not exist or the
// kernel refuses.
Status pinCurrentThread(int core);
// The core the calling thread runs on now (-1 if unknown).
int currentCore();

// Pins the calling thread to `core` for its lifetime, then gives the thread back the mask it
// had. For a process's main thread while it runs one side of the split: every thread it or
// a library makes meanwhile (llvmpipe's rasterizers for a GL context made on it) inherits the
// core, where an unpinned one would run on the other side's core too.
class ScopedThreadPin {
public:
    explicit ScopedThreadPin(int core);
    ~ScopedThreadPin();
    ScopedThreadPin(const ScopedThreadPin&) = delete;
    ScopedThreadPin& operator=(const ScopedThreadPin&) = delete;
    // Empty when the thread is pinned; else why not (it then runs with its old mask).
    const std::string& error() const { return m_error; }

private:
    std::vector<int> m_previous;  // the cores of the mask before, empty if it could not be read
    std::string m_error;
};

}  // namespace qvr::runtime
