// libFuzzer target for the Mahimahi trace reader and the link grammar in front of it (both in
// core, read by net's link emulator and the simulator alike): any text either parses to a
// non-decreasing trace with a positive period or yields an error message, and any text either
// parses to a link spec within the grammar's ranges or yields an error message.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "qvr/core/check.h"
#include "qvr/core/link_spec.h"
#include "qvr/core/mahimahi.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto trace = qvr::parseMahimahiTrace(text, "fuzz");
    if (trace) {
        QVR_CHECK(!trace->stamps_ms.empty() && trace->period_ms > 0);
        for (size_t i = 1; i < trace->stamps_ms.size(); ++i) {
            QVR_CHECK(trace->stamps_ms[i] >= trace->stamps_ms[i - 1]);
        }
        QVR_CHECK(trace->meanBps() > 0);
    } else {
        QVR_CHECK(!trace.error().empty());
    }
    // The grammar alone: parseLinkSpec opens no file.
    auto link = qvr::parseLinkSpec(std::string(text));
    if (link) {
        QVR_CHECK(std::isfinite(link->rate_bps) && link->rate_bps >= 0);
        QVR_CHECK(link->delay_ms >= 0 && link->jitter_ms >= 0 && link->loss >= 0 &&
                  link->loss < 1 && link->queue_bytes > 0);
        QVR_CHECK(link->profile != "trace" || !link->trace_path.empty());
        QVR_CHECK(link->trace == nullptr);
    } else {
        QVR_CHECK(!link.error().empty());
    }
    return 0;
}
