// Cryptomatte ID mattes (cryptomatte.h).
#include "core/render/cryptomatte.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "core/render/shade.h"

namespace sylva {

uint32_t murmurHash3(std::string_view text, uint32_t seed)
{
    constexpr uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
    const auto rotl = [](uint32_t x, int r) { return (x << r) | (x >> (32 - r)); };
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size(), blocks = n / 4;
    uint32_t h = seed;
    for (size_t i = 0; i < blocks; ++i) {   // little-endian 4-byte blocks
        const unsigned char* b = bytes + 4 * i;
        uint32_t k = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
        k *= c1;
        k = rotl(k, 15);
        k *= c2;
        h ^= k;
        h = rotl(h, 13);
        h = h * 5u + 0xe6546b64u;
    }
    const unsigned char* tail = bytes + 4 * blocks;
    uint32_t k = 0;
    switch (n & 3u) {
    case 3: k ^= uint32_t(tail[2]) << 16; [[fallthrough]];
    case 2: k ^= uint32_t(tail[1]) << 8; [[fallthrough]];
    case 1:
        k ^= uint32_t(tail[0]);
        k *= c1;
        k = rotl(k, 15);
        k *= c2;
        h ^= k;
    }
    h ^= uint32_t(n);
    h ^= h >> 16;   // fmix32
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

float cryptomatteId(uint32_t hash)
{
    const uint32_t exponent = std::clamp((hash >> 23) & 0xffu, 1u, 254u);
    const uint32_t bits = (hash & 0x807fffffu) | (exponent << 23);
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

std::string cryptomatteHex(float id)
{
    uint32_t bits;
    std::memcpy(&bits, &id, 4);
    char hex[9];
    std::snprintf(hex, sizeof hex, "%08x", bits);
    return hex;
}

std::string cryptomatteKey(std::string_view typeName)
{
    char hex[9];
    std::snprintf(hex, sizeof hex, "%08x", murmurHash3(typeName));
    return std::string(hex, 7);
}

MatteHit matteHit(const RenderView& v, const Hit& hit)
{
    MatteHit m;
    m.kind = hit.kind;
    switch (SurfaceKind(hit.kind)) {
    case SurfaceKind::Spheres: m.object = hit.prim; break;
    case SurfaceKind::Instances:
    case SurfaceKind::Landscape: {
        const bool land = SurfaceKind(hit.kind) == SurfaceKind::Landscape;
        const uint32_t geometry = land ? v.tilePlants[hit.nested[1]].geometry : instancesHitMap(v, hit).geometry;
        m.species = v.geometries[geometry].species;
        m.object = land ? hit.nested[0] : hit.inst;
        m.plant = land ? hit.nested[1] : 0u;
        m.leaf = v.materials[v.triMaterial[hit.prim]].isLeaf != 0u ? 1u : 0u;
        break;
    }
    default: break;   // the ground, the terrain: one surface each
    }
    return m;
}

namespace {

struct MatteHitHash {
    size_t operator()(const MatteHit& m) const
    {
        uint64_t h = 1469598103934665603ull;
        for (uint32_t x : {m.kind, m.species, m.object, m.plant, m.leaf}) h = (h ^ x) * 1099511628211ull;
        return size_t(h);
    }
};

} // namespace

MatteFilm renderMatteFilm(const RenderView& v)
{
    MatteFilm film;
    film.width = v.width;
    film.height = v.height;
    const int sBegin = v.sampleBegin, sEnd = sampleEndOf(v);
    const float share = 1.0f / float(std::max(1, sEnd - sBegin));
    // Per row: each pixel's distinct hits (linear search: a pixel sees few) with their sample counts.
    struct RowEntry {
        MatteHit hit;
        int count;
    };
    std::vector<std::vector<RowEntry>> rows(size_t(v.height));
    std::vector<std::vector<uint32_t>> rowCounts(size_t(v.height));
    tbb::parallel_for(tbb::blocked_range<int>(0, v.height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) {
            std::vector<RowEntry>& row = rows[size_t(y)];
            std::vector<uint32_t>& counts = rowCounts[size_t(y)];
            counts.resize(size_t(v.width));
            for (int x = 0; x < v.width; ++x) {
                const size_t first = row.size();
                for (int s = sBegin; s < sEnd; ++s) {
                    Hit hit{};
                    if (!intersectStage(v, sampleRay(v, x, y, s), hit)) continue;
                    const MatteHit m = matteHit(v, hit);
                    auto it = std::find_if(row.begin() + std::ptrdiff_t(first), row.end(), [&](const RowEntry& e) { return e.hit == m; });
                    if (it == row.end()) row.push_back({m, 1});
                    else ++it->count;
                }
                counts[size_t(x)] = uint32_t(row.size() - first);
            }
        }
    });
    std::unordered_map<MatteHit, uint32_t, MatteHitHash> index;
    film.start.reserve(size_t(v.width) * size_t(v.height) + 1);
    film.start.push_back(0);
    for (int y = 0; y < v.height; ++y) {
        size_t e = 0;
        for (int x = 0; x < v.width; ++x) {
            for (uint32_t k = 0; k < rowCounts[size_t(y)][size_t(x)]; ++k, ++e) {
                const RowEntry& re = rows[size_t(y)][e];
                auto [it, added] = index.try_emplace(re.hit, uint32_t(film.hits.size()));
                if (added) film.hits.push_back(re.hit);
                film.entries.push_back({it->second, float(re.count) * share});
            }
            film.start.push_back(uint32_t(film.entries.size()));
        }
        rows[size_t(y)] = {};
    }
    return film;
}

CryptomatteRanks rankCryptomatte(const MatteFilm& film, const std::vector<float>& idOf, int minRanks, int maxRanks)
{
    CryptomatteRanks out;
    out.width = film.width;
    out.height = film.height;
    const size_t n = size_t(film.width) * size_t(film.height);
    const auto bitsOf = [](float f) {
        uint32_t b;
        std::memcpy(&b, &f, 4);
        return b;
    };
    // Per pixel: its IDs with their summed coverage, sorted (highest coverage first, then the smaller ID bits).
    std::vector<std::pair<float, float>> merged;   // (id, coverage)
    std::vector<uint32_t> firstOf(n + 1, 0);
    std::vector<std::pair<float, float>> all;
    for (size_t p = 0; p < n; ++p) {
        merged.clear();
        for (uint32_t e = film.start[p]; e < film.start[p + 1]; ++e) {
            const float id = idOf[film.entries[e].hit];
            auto it = std::find_if(merged.begin(), merged.end(), [&](const auto& m) { return bitsOf(m.first) == bitsOf(id); });
            if (it == merged.end()) merged.push_back({id, film.entries[e].coverage});
            else it->second += film.entries[e].coverage;
        }
        std::sort(merged.begin(), merged.end(), [&](const auto& a, const auto& b) {
            return a.second != b.second ? a.second > b.second : bitsOf(a.first) < bitsOf(b.first);
        });
        all.insert(all.end(), merged.begin(), merged.end());
        firstOf[p + 1] = uint32_t(all.size());
    }
    int most = 0;
    for (size_t p = 0; p < n; ++p) most = std::max(most, int(firstOf[p + 1] - firstOf[p]));
    out.ranks = std::clamp((most + 1) / 2 * 2, minRanks, std::max(minRanks, maxRanks));
    out.pairs.assign(n * size_t(out.ranks) * 2, 0.0f);
    for (size_t p = 0; p < n; ++p) {
        float* d = &out.pairs[p * size_t(out.ranks) * 2];
        const uint32_t count = std::min(firstOf[p + 1] - firstOf[p], uint32_t(out.ranks));
        for (uint32_t r = 0; r < count; ++r) {
            d[2 * r] = all[firstOf[p] + r].first;
            d[2 * r + 1] = all[firstOf[p] + r].second;
        }
    }
    return out;
}

} // namespace sylva
