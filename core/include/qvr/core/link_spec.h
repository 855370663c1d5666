// The link between server and headset as a command line names it (`--net`): one grammar for
// net's link emulator, the paper simulator's links and the simulator's model of the runtime.
// Each reader takes what it models of a spec and says what it does not (docs/NETWORK.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "qvr/core/expected.h"
#include "qvr/core/mahimahi.h"

namespace qvr {

// What a spec names. The fault fields are net's emulator's (the simulator models none of them).
struct LinkSpec {
    std::string name = "none";  // the profile part as written: "wifi", "rate:50", "trace:P@5"
    std::string profile;        // "none", "wifi", "lte" (also for "4g"), "5g", "rate", "trace"
    double rate_bps = 0.0;      // 0: no rate limit (and for a trace)
    std::string trace_path;     // profile "trace"
    std::shared_ptr<const MahimahiTrace> trace;  // loaded by loadLinkSpec; replaces rate_bps
    double trace_target_bps = 0.0;               // rescale the trace to this mean; 0: as recorded
    double delay_ms = 0.0;                       // one way, after the queue
    double jitter_ms = 0.0;                      // uniform in [-jitter, +jitter], order kept
    double loss = 0.0;                           // per-packet drop probability before the queue
    int64_t queue_bytes = 4 << 20;               // drop-tail bottleneck buffer
    int64_t max_in_flight_bytes = 64 << 20;      // the delay line (rate × delay) is bounded too
    uint64_t seed = 1;
    // Faults, each off at 0; each draws from a seeded stream of its own, so turning one on does
    // not change which packets random loss, jitter or another fault pick.
    // Gilbert-Elliott burst loss: per packet Good→Bad with ge_p, Bad→Good with ge_r; a packet
    // sent in Bad is lost with ge_loss_bad (1: all). Long-run loss ge_loss_bad · ge_p /
    // (ge_p + ge_r), mean Bad run 1 / ge_r packets. The chain steps on every packet sent,
    // whether random loss took it or not: the two losses are independent.
    double ge_p = 0.0;
    double ge_r = 0.0;
    double ge_loss_bad = 1.0;
    // With probability `reorder` a packet is held reorder_ms longer, outside the order-keeping
    // delay line: packets sent after it overtake it.
    double reorder = 0.0;
    double reorder_ms = 5.0;
    double duplicate = 0.0;  // a packet is delivered twice (the copy right after it)
    // Delay spikes (a Wi-Fi stall): packets sent during the last spike_len_ms of every
    // spike_every_ms (from the link's first packet) wait spike_extra_ms more, order kept.
    double spike_every_ms = 0.0;
    double spike_len_ms = 0.0;
    double spike_extra_ms = 0.0;
    int options = 0;  // how many ",key=value" options the spec gave
    bool faulty() const {
        return ge_p > 0.0 || reorder > 0.0 || duplicate > 0.0 || spike_every_ms > 0.0;
    }
    bool shaped() const {
        return rate_bps > 0.0 || trace != nullptr || delay_ms > 0.0 || jitter_ms > 0.0 ||
               loss > 0.0 || faulty();
    }
};

// The grammar:
//   SPEC    := PROFILE ( "," OPTION )*
//   PROFILE := "none" | "wifi" (200 Mbit/s) | "lte" | "4g" (100) | "5g" (500)   — paper Table 2
//            | "rate:" MBPS                        MBPS in [0.001, 1e6] Mbit/s
//            | "trace:" PATH [ "@" MBPS ]           a Mahimahi file (mahimahi.h), rescaled to a
//                                                   mean of MBPS when given
//   OPTION  := "delay_ms=" D | "jitter_ms=" J        D, J in [0, 10000] ms
//            | "loss=" P | "dup=" P                 P in [0, 1)
//            | "queue_kb=" Q                        Q in [1, 1048576] KiB
//            | "seed=" S                            an unsigned integer
//            | "ge=" P ":" R [ ":" LOSS_BAD ]       Gilbert-Elliott, P in [0, 1), R and LOSS_BAD
//                                                   in (0, 1] (LOSS_BAD 1 by default)
//            | "reorder=" P [ ":" MS ]              P in [0, 1), MS in (0, 10000] (default 5)
//            | "spike=" EVERY ":" LEN ":" EXTRA     ms, 0 < LEN <= EVERY <= 3600000,
//                                                   0 < EXTRA <= 10000
// Numbers are finite decimals (no NaN or infinities). A trace without "@MBPS" plays at its
// recorded mean in net and in the runtime model; the paper simulator rescales it to the LTE
// profile's 100 Mbit/s. A trace starts (its time 0) with the first packet sent through the link.
// parseLinkSpec reads the grammar alone and touches no file.
Expected<LinkSpec> parseLinkSpec(const std::string& spec);
// parseLinkSpec, then the trace file read into LinkSpec::trace (errors name the file and line).
Expected<LinkSpec> loadLinkSpec(const std::string& spec);
// The named profiles: "none", "wifi", "lte", "5g" ("4g" is lte's other name).
const std::vector<std::string>& linkProfileNames();

}  // namespace qvr
