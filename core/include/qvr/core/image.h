// Images: tightly packed, row-major, interleaved channels. The unit of exchange between the
// renderer, the codec and the compositor.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include "qvr/core/check.h"

namespace qvr {

// Pixel storage starts on a 64-byte cache line, so that vector kernels can use aligned and
// streaming (non-temporal) stores on rows whose byte offset is a multiple of 64.
inline constexpr size_t kImageAlignment = 64;

template <typename T>
struct CacheLineAllocator {
    using value_type = T;
    CacheLineAllocator() = default;
    template <typename U>
    CacheLineAllocator(const CacheLineAllocator<U>&) {}  // NOLINT: rebinding is implicit
    T* allocate(size_t n) {
        return static_cast<T*>(::operator new (n * sizeof(T), std::align_val_t{kImageAlignment}));
    }
    void deallocate(T* p, size_t) { ::operator delete (p, std::align_val_t{kImageAlignment}); }
    template <typename U>
    bool operator==(const CacheLineAllocator<U>&) const {
        return true;
    }
};

template <typename T, int kChannels>
class Image {
public:
    using Pixel = T;
    static constexpr int channels = kChannels;

    Image() = default;
    Image(int width, int height) { resize(width, height); }

    void resize(int width, int height) {
        QVR_CHECK(width >= 0 && height >= 0);
        m_width = width;
        m_height = height;
        m_data.assign(static_cast<size_t>(width) * static_cast<size_t>(height) * kChannels, T{});
    }

    int width() const { return m_width; }
    int height() const { return m_height; }
    bool empty() const { return m_width == 0 || m_height == 0; }
    size_t strideElems() const { return static_cast<size_t>(m_width) * kChannels; }

    T* row(int y) { return m_data.data() + static_cast<size_t>(y) * strideElems(); }
    const T* row(int y) const { return m_data.data() + static_cast<size_t>(y) * strideElems(); }
    T& at(int x, int y, int c) { return row(y)[static_cast<size_t>(x) * kChannels + c]; }
    T at(int x, int y, int c) const { return row(y)[static_cast<size_t>(x) * kChannels + c]; }

    T* data() { return m_data.data(); }
    const T* data() const { return m_data.data(); }
    size_t sizeBytes() const { return m_data.size() * sizeof(T); }

private:
    int m_width = 0;
    int m_height = 0;
    std::vector<T, CacheLineAllocator<T>> m_data;
};

using ImageRgba8 = Image<uint8_t, 4>;
using ImageRgbF = Image<float, 3>;

}  // namespace qvr
