// Images are header-only templates; this unit instantiates the common ones once.
#include "qvr/core/image.h"

namespace qvr {
template class Image<uint8_t, 4>;
template class Image<float, 3>;
}  // namespace qvr
