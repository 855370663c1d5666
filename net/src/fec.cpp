// Reed-Solomon erasure coding through Intel ISA-L (see the header).
#include "qvr/net/fec.h"

#include <isa-l/erasure_code.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "qvr/core/check.h"

namespace qvr::net {
namespace {

constexpr int kMaxRows = kFecBlockData + kFecMaxParity;

// The (k + m) × k Cauchy generator: identity on top (the code is systematic), then parity rows.
// Row k + j depends only on j and k, so a block's first parity shards are the same whatever m.
void generator(int k, int m, std::array<uint8_t, kMaxRows * kFecBlockData>& a) {
    gf_gen_cauchy1_matrix(a.data(), k + m, k);
}

}  // namespace

int fecBlockCount(int data_packets) {
    return (data_packets + kFecBlockData - 1) / kFecBlockData;
}

int fecBlockSize(int data_packets, int block) {
    return std::min(kFecBlockData, data_packets - fecBlockFirst(block));
}

void fecEncode(int len, std::span<const uint8_t* const> data, std::span<uint8_t* const> parity) {
    const int k = static_cast<int>(data.size());
    const int m = static_cast<int>(parity.size());
    QVR_CHECK(k >= 1 && k <= kFecBlockData && m >= 1 && m <= kFecMaxParity && len > 0);
    std::array<uint8_t, kMaxRows * kFecBlockData> a{};
    generator(k, m, a);
    std::vector<uint8_t> tables(static_cast<size_t>(32 * k * m));
    ec_init_tables(k, m, a.data() + k * k, tables.data());
    // ISA-L takes non-const source pointers but only reads them.
    std::array<uint8_t*, kFecBlockData> src{};
    for (int i = 0; i < k; ++i) {
        src[static_cast<size_t>(i)] = const_cast<uint8_t*>(data[static_cast<size_t>(i)]);
    }
    std::array<uint8_t*, kFecMaxParity> dst{};
    std::copy(parity.begin(), parity.end(), dst.begin());
    ec_encode_data(len, k, m, tables.data(), src.data(), dst.data());
}

bool fecReconstruct(int len, std::span<uint8_t* const> data, const std::vector<bool>& have_data,
                    std::span<const uint8_t* const> parity, const std::vector<bool>& have_parity) {
    const int k = static_cast<int>(data.size());
    const int m = static_cast<int>(parity.size());
    QVR_CHECK(k >= 1 && k <= kFecBlockData && m >= 1 && m <= kFecMaxParity && len > 0);
    QVR_CHECK(static_cast<int>(have_data.size()) == k && static_cast<int>(have_parity.size()) == m);
    // The first k shards present (data first), and the data shards to rebuild.
    std::array<int, kFecBlockData> rows{};
    std::array<uint8_t*, kFecBlockData> src{};
    std::array<int, kFecBlockData> lost{};
    int n = 0, nlost = 0;
    for (int i = 0; i < k; ++i) {
        if (have_data[static_cast<size_t>(i)]) {
            rows[static_cast<size_t>(n)] = i;
            src[static_cast<size_t>(n++)] = data[static_cast<size_t>(i)];
        } else {
            lost[static_cast<size_t>(nlost++)] = i;
        }
    }
    if (nlost == 0) {
        return true;
    }
    for (int j = 0; j < m && n < k; ++j) {
        if (have_parity[static_cast<size_t>(j)]) {
            rows[static_cast<size_t>(n)] = k + j;
            src[static_cast<size_t>(n++)] = const_cast<uint8_t*>(parity[static_cast<size_t>(j)]);
        }
    }
    if (n < k) {
        return false;
    }
    std::array<uint8_t, kMaxRows * kFecBlockData> a{};
    generator(k, m, a);
    // The rows of the shards we hold, inverted, map them back to the data.
    std::vector<uint8_t> b(static_cast<size_t>(k * k)), inv(static_cast<size_t>(k * k));
    for (int r = 0; r < k; ++r) {
        std::copy_n(a.data() + rows[static_cast<size_t>(r)] * k, k,
                    b.data() + static_cast<ptrdiff_t>(r) * k);
    }
    if (gf_invert_matrix(b.data(), inv.data(), k) != 0) {
        return false;  // cannot happen with a Cauchy generator
    }
    std::vector<uint8_t> decode(static_cast<size_t>(nlost * k));
    std::array<uint8_t*, kFecBlockData> out{};
    for (int e = 0; e < nlost; ++e) {
        std::copy_n(inv.data() + lost[static_cast<size_t>(e)] * k, k,
                    decode.data() + static_cast<ptrdiff_t>(e) * k);
        out[static_cast<size_t>(e)] = data[static_cast<size_t>(lost[static_cast<size_t>(e)])];
    }
    std::vector<uint8_t> tables(static_cast<size_t>(32 * k * nlost));
    ec_init_tables(k, nlost, decode.data(), tables.data());
    ec_encode_data(len, k, nlost, tables.data(), src.data(), out.data());
    return true;
}

int fecParityFor(int block_data, double loss, const FecPolicy& policy) {
    if (!policy.enabled || block_data <= 0 || !(loss >= policy.min_loss)) {
        return 0;
    }
    const double p = std::min(loss, 0.5);
    const int cap = std::clamp(
        std::min(policy.max_parity, static_cast<int>(std::ceil(policy.max_overhead * block_data))),
        0, kFecMaxParity);
    const int floor = std::min(std::max(policy.min_parity, 0), cap);
    for (int m = floor; m < cap; ++m) {
        // P(more than m of n = k + m lost), binomial; terms by recurrence.
        const int n = block_data + m;
        double term = std::pow(1.0 - p, n);  // P(0 lost)
        double at_most = term;
        for (int i = 1; i <= m; ++i) {
            term *= (static_cast<double>(n - i + 1) / i) * (p / (1.0 - p));
            at_most += term;
        }
        if (1.0 - at_most <= policy.target_residual) {
            return m;
        }
    }
    return cap;
}

}  // namespace qvr::net
