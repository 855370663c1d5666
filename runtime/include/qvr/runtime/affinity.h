// Pinning the headset and the server each to its own core (issue 6: the headset's budget is not
// the server's). Threads a pinned thread creates (llvmpipe's rasterizers, x264) inherit the mask.
#pragma once

#include "qvr/core/expected.h"

namespace qvr::runtime {

int onlineCores();
// Pins the calling thread to `core` (0-based); an error when the core does not exist or the
// kernel refuses.
Status pinCurrentThread(int core);
// The core the calling thread runs on now (-1 if unknown).
int currentCore();

}  // namespace qvr::runtime
