// Forward error correction for the media streams (docs/PROTOCOL.md §Forward error correction):
// a systematic Reed-Solomon erasure code over GF(2^8) from Intel ISA-L (Cauchy matrix), so any
// k of a block's k data + m parity packets rebuild its k data packets without a round trip.
// A stream frame of k data packets is cut into blocks of at most kFecBlockData packets; each
// block gets the same number m of parity packets. Every shard is kMediaChunkBytes long (the
// frame's last data packet is zero-padded for the code).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace qvr::net {

inline constexpr int kFecBlockData = 64;  // data packets per block (k + m ≤ 255 for GF(2^8))
inline constexpr int kFecMaxParity = 32;  // parity packets per block (a header byte's limit)

int fecBlockCount(int data_packets);
// Data packets of block b: [fecBlockFirst(b), fecBlockFirst(b) + fecBlockSize(k, b)).
inline int fecBlockFirst(int block) {
    return block * kFecBlockData;
}
int fecBlockSize(int data_packets, int block);

// m parity shards of len bytes for the k data shards (each len bytes); 1 ≤ k ≤ kFecBlockData,
// 1 ≤ m ≤ kFecMaxParity.
void fecEncode(int len, std::span<const uint8_t* const> data, std::span<uint8_t* const> parity);

// Rebuilds the missing data shards of one block in place. data: k buffers of len bytes,
// have_data[i] says which hold their shard; parity: m buffers, have_parity[j] likewise. False
// (nothing written) when fewer than k of the k + m shards are present.
bool fecReconstruct(int len, std::span<uint8_t* const> data, const std::vector<bool>& have_data,
                    std::span<const uint8_t* const> parity, const std::vector<bool>& have_parity);

// How many parity packets per block the server adds for a measured packet loss rate: the
// smallest m with P(more than m of k + m lost) ≤ target_residual under independent loss at
// `loss`, between a floor (min_parity once any loss is measured) and a cap (max_parity, and at
// most max_overhead · k). No loss measured (below min_loss) → 0: a clean link pays nothing.
struct FecPolicy {
    bool enabled = true;
    double target_residual = 0.01;
    double min_loss = 0.001;
    int min_parity = 1;
    int max_parity = 16;
    double max_overhead = 1.0;  // parity packets per data packet
};
int fecParityFor(int block_data, double loss, const FecPolicy& policy);

}  // namespace qvr::net
