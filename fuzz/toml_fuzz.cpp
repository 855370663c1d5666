// libFuzzer target for the TOML configs users hand to qvr (docs/CONFIG.md): any text is parsed
// by toml++ and read as a headset profile (--hmd FILE) and as a hardware config (--hardware
// FILE); each either yields a profile that passes its own range checks or an error message, and
// a profile that loads survives hmdProfileToToml → parseHmdProfile.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "qvr/core/check.h"
#include "qvr/core/config.h"
#include "qvr/foveation/hmd_profile.h"
#include "qvr/sim/hardware.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto table = qvr::parseTomlText(text, "fuzz.toml");
    if (!table.ok())
        QVR_CHECK(!table.error().empty());

    auto hmd = qvr::parseHmdProfile(text, "fuzz.toml");
    if (hmd.ok()) {
        auto again = qvr::parseHmdProfile(qvr::hmdProfileToToml(*hmd), "again.toml");
        QVR_CHECK(again.ok());
    } else {
        QVR_CHECK(!hmd.error().empty());
    }

    auto hardware = qvr::parseHardwareConfig(text, "fuzz.toml", 500.0);
    if (!hardware.ok())
        QVR_CHECK(!hardware.error().empty());
    return 0;
}
