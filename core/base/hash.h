// Integer hashing shared by the sample generators and the procedural textures (host and device).
#pragma once

#include <stdint.h>

#include "core/base/defines.h"

namespace sylva {

// The finalizing rounds of a 32-bit hash (xor-shift and multiply, the constants of Wellons' "lowbias32"
// search): every input bit flips about half the output bits.
SYLVA_HD SYLVA_INLINE uint32_t hashFinalize(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return h;
}

} // namespace sylva
