// Little-endian byte writer and a bounds-checked reader: the only way protocol code touches raw
// bytes, so no decoder indexes past what it was given.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace qvr::net::detail {

class ByteWriter {
public:
    explicit ByteWriter(std::vector<uint8_t>& out) : m_out(out) {}
    void u8(uint8_t v) { m_out.push_back(v); }
    void u16(uint16_t v) { putLe(v, 2); }
    void u32(uint32_t v) { putLe(v, 4); }
    void u64(uint64_t v) { putLe(v, 8); }
    void i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
    void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
    // resize + memcpy rather than insert: GCC 12 at -O3 misreads insert into a fresh vector as
    // an overflow (-Wstringop-overflow), a false positive that -Werror would turn into a failure.
    void bytes(std::span<const uint8_t> b) {
        const size_t old = m_out.size();
        m_out.resize(old + b.size());
        if (!b.empty()) {
            std::memcpy(m_out.data() + old, b.data(), b.size());
        }
    }

private:
    void putLe(uint64_t v, int n) {
        for (int i = 0; i < n; ++i) {
            m_out.push_back(static_cast<uint8_t>(v >> (8 * i)));
        }
    }
    std::vector<uint8_t>& m_out;
};

// Every read checks the remaining length; after the first short read all reads fail and
// ok() stays false, so a decoder checks once at the end.
class ByteReader {
public:
    explicit ByteReader(std::span<const uint8_t> in) : m_in(in) {}
    bool ok() const { return m_ok; }
    size_t remaining() const { return m_in.size() - m_pos; }
    uint8_t u8() { return static_cast<uint8_t>(getLe(1)); }
    uint16_t u16() { return static_cast<uint16_t>(getLe(2)); }
    uint32_t u32() { return static_cast<uint32_t>(getLe(4)); }
    uint64_t u64() { return getLe(8); }
    int32_t i32() { return static_cast<int32_t>(u32()); }
    float f32() { return std::bit_cast<float>(u32()); }
    template <size_t N>
    void bytes(std::array<uint8_t, N>& out) {
        if (!take(N)) {
            out.fill(0);
            return;
        }
        std::memcpy(out.data(), m_in.data() + m_pos - N, N);
    }

private:
    bool take(size_t n) {
        if (!m_ok || remaining() < n) {
            m_ok = false;
            return false;
        }
        m_pos += n;
        return true;
    }
    uint64_t getLe(int n) {
        if (!take(static_cast<size_t>(n))) {
            return 0;
        }
        uint64_t v = 0;
        for (int i = 0; i < n; ++i) {
            v |=
                static_cast<uint64_t>(m_in[m_pos - static_cast<size_t>(n) + static_cast<size_t>(i)])
                << (8 * i);
        }
        return v;
    }
    std::span<const uint8_t> m_in;
    size_t m_pos = 0;
    bool m_ok = true;
};

}  // namespace qvr::net::detail
