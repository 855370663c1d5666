// libFuzzer target for the Mahimahi trace reader: any text either parses to a non-decreasing
// trace with a positive period or yields an error message.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "qvr/core/check.h"
#include "qvr/net/mahimahi.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto trace = qvr::net::parseMahimahiTrace(text, "fuzz");
    if (trace) {
        QVR_CHECK(!trace->stamps_ms.empty() && trace->period_ms > 0);
        for (size_t i = 1; i < trace->stamps_ms.size(); ++i) {
            QVR_CHECK(trace->stamps_ms[i] >= trace->stamps_ms[i - 1]);
        }
        QVR_CHECK(trace->meanBps() > 0);
    } else {
        QVR_CHECK(!trace.error().empty());
    }
    return 0;
}
