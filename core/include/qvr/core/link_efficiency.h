// The share of a link's nominal capacity a frame's payload gets (protocol headers, MAC
// contention, codec framing), fitted once to the paper's Table 1 — the one efficiency the
// simulator's links (sim/network.h) and `qvr control`'s cost model both apply to every nominal
// rate (docs/MODEL.md §5).
#pragma once

#include <vector>

namespace qvr {

// One row of Table 1: the static design's background size and its measured T_remote on Wi-Fi.
struct Table1Row {
    const char* app;
    double background_bytes;  // KB as printed, taken as 1000 bytes
    double t_remote_ms;
};
const std::vector<Table1Row>& table1Rows();

// η, fitted by least squares over Table 1's five rows at Wi-Fi's nominal 200 Mbit/s:
// T = bits / (η·C), so 1/(η·C) = Σ bits·T / Σ bits² (η ≈ 0.687, every row within 1.3%).
double calibratedLinkEfficiency();

}  // namespace qvr
