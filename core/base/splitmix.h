#pragma once
// splitmix64 (Steele, Lea, Flood 2014): a fixed sequence on every platform, the one generator of the
// scatter tool, the landscape's tile populations and the pruning order.
#include <cstdint>

#include "core/base/defines.h"

namespace sylva {

struct SplitMix64 {
    uint64_t state;
    SYLVA_HD uint64_t next()
    {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    SYLVA_HD double unit() { return double(next() >> 11) * 0x1.0p-53; }   // [0, 1)
};

} // namespace sylva
