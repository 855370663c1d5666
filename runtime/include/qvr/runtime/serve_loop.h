// How long a render-server process serves, and what it tells a game-server fleet while it does:
// with Agones' SDK sidecar (docs/DEPLOY.md), Ready before it takes headsets, Health all along,
// Shutdown after.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "qvr/core/expected.h"
#include "qvr/net/agones_sdk.h"

namespace qvr::runtime {

// Health pings while the server serves, more often than the fleet's health period
// (deploy/agones; scripts/check_agones.py checks it).
inline constexpr int kAgonesHealthPeriodMs = 2000;

// The SDK sidecar's address from the AGONES_SDK_HTTP_PORT value `port_env` (may be null).
Expected<net::AgonesSdkOptions> agonesSdkOptions(const char* port_env);

// What the loop reports as it goes: Ready sent (with the sidecar's port), Shutdown refused.
struct ServeEvents {
    std::function<void(uint16_t port)> ready_sent;
    std::function<void(const std::string& why)> shutdown_failed;
};

// Serves until `stop` is set, or until `duration_s` seconds have passed when it is above 0;
// with `sdk`, Ready first (an error when the sidecar refuses it: nothing was served), Health
// every kAgonesHealthPeriodMs, Shutdown after.
Status serveUntilStopped(const std::atomic<bool>& stop, double duration_s, net::AgonesSdk* sdk,
                         const ServeEvents& events);

}  // namespace qvr::runtime
