// Cryptomatte ID mattes (Jonah Friedman, Andrew C. Jones, Psyop, "Cryptomatte" specification): the names' hash
// and float IDs, what each camera sample's first hit is, and the ranked coverage of a pixel's IDs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/render/render_view.h"

namespace sylva {

// MurmurHash3_x86_32 (Austin Appleby) of the bytes of `text` with `seed`: the specification's hash of a name.
uint32_t murmurHash3(std::string_view text, uint32_t seed = 0);

// The specification's uint32_to_float32 conversion: the hash's bits as a float with the exponent clamped
// to [1, 254], so that no ID is zero, denormal, infinite or NaN.
float cryptomatteId(uint32_t hash);

// The manifest's form of an ID: the float's bits as 8 lower-case hexadecimal digits.
std::string cryptomatteHex(float id);

// The metadata key of a Cryptomatte type (e.g. "CryptoObject"): the first 7 hexadecimal digits of the
// MurmurHash3 of its name (as Blender and the other writers choose it), for the header's
// "cryptomatte/<key>/name", ".../hash", ".../conversion" and ".../manifest".
std::string cryptomatteKey(std::string_view typeName);

// What a camera sample's first hit is, for naming it: the surface kind that recorded it and, for plants, the
// scene instance (or the landscape's cell and plant), the species and whether the triangle's material is a leaf.
struct MatteHit {
    uint32_t kind = 0;        // SurfaceKind
    uint32_t species = 0;     // Instances, Landscape: index into Scene::species
    uint32_t object = 0;      // Instances: the top-level instance (Scene::instances); Landscape: the cell; Spheres: the sphere
    uint32_t plant = 0;       // Landscape: the plant (RenderView::tilePlants)
    uint32_t leaf = 0;        // Instances, Landscape: the material is a leaf
    bool operator==(const MatteHit&) const = default;
};

// The first hit of a camera ray (found: intersectStage's answer) as a MatteHit.
MatteHit matteHit(const RenderView& v, const Hit& hit);

// A frame's camera samples by what they hit first: per pixel (row-major, top row first) the distinct hits
// and each one's share of the pixel's samples (the box filter the other passes use: count / samples).
// Samples that hit nothing (the sky) are not listed: a pixel's shares sum to 1 minus its sky share.
struct MatteFilm {
    int width = 0, height = 0;
    std::vector<MatteHit> hits;          // the distinct hits of the frame
    std::vector<uint32_t> start;         // pixel p's entries: [start[p], start[p + 1]) of `entries`
    struct Entry {
        uint32_t hit;                    // into hits
        float coverage;
    };
    std::vector<Entry> entries;
};

// The camera samples renderFilm takes (the same positions, sampleRay; samples v.sampleBegin .. sampleEnd), traced to their
// first hit on the CPU, in parallel over rows.
MatteFilm renderMatteFilm(const RenderView& v);

// One Cryptomatte type of a frame: per pixel `ranks` (ID, coverage) pairs, the IDs of a MatteFilm's hits (idOf[hit],
// hits of the same ID merged), highest coverage first (ties: the smaller ID bits first), unused ranks (0, 0).
struct CryptomatteRanks {
    int width = 0, height = 0, ranks = 0;
    std::vector<float> pairs;            // width * height * ranks * 2: id0, coverage0, id1, coverage1, ...
};
// ranks: the frame's largest count of distinct IDs in a pixel, rounded up to even, at least minRanks and at most
// maxRanks (a pixel with more keeps its maxRanks largest).
CryptomatteRanks rankCryptomatte(const MatteFilm& film, const std::vector<float>& idOf, int minRanks = 6, int maxRanks = 16);

} // namespace sylva
