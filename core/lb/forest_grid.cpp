// The forest-level LB grid (forest_grid.h).
#include "core/lb/forest_grid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/lb_node.h"
#include "core/lb/lb_solver.h"
#include "core/lb/omega.h"

namespace sylva::lb {

ForestSpecies forestSpecies(const DensityGrid& d)
{
    ForestSpecies s;
    const GridGeometry& g = d.geometry;
    s.spacing = g.spacing;
    const double cell = g.spacing * g.spacing * g.spacing;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                const float rho = d.density[g.index(i, j, k)];
                if (!(rho > 0.0f)) continue;
                s.biomass += double(rho) * cell;
                const glm::dvec3 c = g.origin + g.spacing * glm::dvec3(i, j, k);
                lo = glm::min(lo, c - 0.5 * g.spacing);
                hi = glm::max(hi, c + 0.5 * g.spacing);
            }
    if (s.biomass > 0.0) s.boxMin = lo, s.boxMax = hi;
    return s;
}

double plantExtinctionVolume(const ForestSpecies& s, float scale)
{
    const double k = double(scale);
    return s.spacing > 0.0 ? s.biomass * k * k * k / (s.spacing * k) : 0.0;
}

void splatDepth(const glm::dvec3& lo, const glm::dvec3& hi, double extinctionVolume, const GridGeometry& g, std::vector<float>& depth)
{
    const glm::dvec3 e = hi - lo;
    const double volume = e.x * e.y * e.z;
    if (!(volume > 0.0) || !(extinctionVolume > 0.0)) return;
    const double h = g.spacing;
    // mean density over a cell = biomass x overlap / (volume x h^3); x (h / fine spacing) = the depth a coarse step crosses.
    const double perOverlap = extinctionVolume / (volume * h * h);
    const glm::ivec3 i0 = glm::max(glm::ivec3(glm::floor((lo - g.origin) / h - 0.5)), glm::ivec3(0));
    const glm::ivec3 i1 = glm::min(glm::ivec3(glm::ceil((hi - g.origin) / h + 0.5)), g.dims - 1);
    for (int i = i0.x; i <= i1.x; ++i)
        for (int j = i0.y; j <= i1.y; ++j)
            for (int k = i0.z; k <= i1.z; ++k) {
                const glm::dvec3 c = g.origin + h * glm::dvec3(i, j, k);
                const glm::dvec3 o = glm::max(glm::min(hi, c + 0.5 * h) - glm::max(lo, c - 0.5 * h), glm::dvec3(0.0));
                const double overlap = o.x * o.y * o.z;
                if (overlap > 0.0) depth[g.index(i, j, k)] += float(perOverlap * overlap);
            }
}

namespace {

// Face factors are capped here: a face the plant alone barely lights can take a large ratio from a little
// light its neighbours scatter onto it.
constexpr float kMaxFaceFactor = 4.0f;

// Face factors need the crown to span this many forest-grid cells across (its larger horizontal
// extent): on coarser lattices a crown is one or two nodes, its faces' ratios are the lattice's, not the
// stand's, and blending them in made the stand's picture worse than no forest grid at all (`sylva study
// scene`: image error 0.25-0.34 at 0.4-1.8 cells a crown against 0.178 without the grid; 0.180 at 2.5, 0.149
// at 3.9); such plants keep their centre factor on every face. (A plant scaled across the threshold changes
// its faces at once; moving it does not.)
constexpr double kMinFaceCells = 3.0;

struct Box {
    glm::dvec3 lo, hi;
    double extinctionVolume;   // biomass / the fine spacing (splatDepth)
};

Box plantBox(const ForestPlant& p, const ForestSpecies& s)
{
    Box b;
    b.lo = p.position + double(p.scale) * s.boxMin;
    b.hi = p.position + double(p.scale) * s.boxMax;
    b.extinctionVolume = plantExtinctionVolume(s, p.scale);
    return b;
}

void splat(const Box& b, const GridGeometry& g, std::vector<float>& depth) { splatDepth(b.lo, b.hi, b.extinctionVolume, g, depth); }

glm::vec3 sample(const LightingGrid& l, const glm::dvec3& p)
{
    const GridGeometry& g = l.geometry;
    const glm::dvec3 u = glm::clamp((p - g.origin) / g.spacing, glm::dvec3(0.0), glm::dvec3(g.dims - 1));
    const glm::ivec3 i0 = glm::min(glm::ivec3(u), g.dims - 2);
    const glm::dvec3 f = u - glm::dvec3(i0);
    glm::vec3 out(0.0f);
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const double w = (o.x ? f.x : 1.0 - f.x) * (o.y ? f.y : 1.0 - f.y) * (o.z ? f.z : 1.0 - f.z);
        const size_t n = g.index(i0.x + o.x, i0.y + o.y, i0.z + o.z);
        for (int ch = 0; ch < 3; ++ch) out[ch] += float(w * double(l.rgb[n * 3 + size_t(ch)]));
    }
    return out;
}

// The LB of docs/LB_MODEL.md on a small grid without wood, single-threaded and scalar through the same node
// collision as the solvers (collideNode): for the hundreds of few-hundred-node windows of a forest, where a
// full solver's setup (page-aligned copies, thread pool per step) costs far more than the steps.
// faces (when given): per node and channel the irradiance on the six axis-aligned faces (kFaceNormals order),
// sum over directions m of f_m x max(0, -c_m . N) / |c_m|: the light arriving at a surface facing N.
// solid (when given): per node, nonzero = opaque black (the ground under a landscape): it holds no light
// and sends none, whatever arrives is absorbed.
LightingGrid solveSmall(const GridGeometry& g, const std::vector<float>& rho, const LbParams& p, int steps,
                        std::vector<float>* faces = nullptr, const std::vector<uint8_t>* solid = nullptr)
{
    const std::vector<float> bc = boundaryOf(p);
    const size_t nodes = g.nodeCount();
    LightingGrid out;
    out.geometry = g;
    out.rgb.assign(nodes * 3, 0.0f);
    auto boundary = [&](int i, int j, int k) {
        return i == 0 || j == 0 || k == 0 || i == g.dims.x - 1 || j == g.dims.y - 1 || k == g.dims.z - 1;
    };
    if (faces) faces->assign(nodes * 3 * kFaces, 0.0f);
    // The channels are independent solves: in parallel (the forest grid's own solve runs alone).
    tbb::parallel_for(0, 3, [&](int c) {
        std::vector<float> a(nodes * kDirections), b;
        const ChannelParams& cp = p.channels[size_t(c)];
        const SymmetricOmega om = symmetricOmega(cp);
        for (int i = 0; i < g.dims.x; ++i)
            for (int j = 0; j < g.dims.y; ++j)
                for (int k = 0; k < g.dims.z; ++k) {
                    const size_t n = g.index(i, j, k);
                    const bool onB = (boundary(i, j, k) || p.warmStart) && !(solid && (*solid)[n]);
                    float* f = &a[n * kDirections];
                    for (int m = 0; m < kDirections; ++m) f[m] = onB ? bc[size_t(m)] : 0.0f;
                }
        b = a;
        for (int t = 0; t < steps; ++t) {
            for (int i = 0; i < g.dims.x; ++i)
                for (int j = 0; j < g.dims.y; ++j)
                    for (int k = 0; k < g.dims.z; ++k) {
                        const size_t n = g.index(i, j, k);
                        float f[kDirections];
                        for (int m = 0; m < kDirections; ++m) f[m] = a[n * kDirections + size_t(m)];
                        if (solid && (*solid)[n]) std::fill(f, f + kDirections, 0.0f);
                        else if (rho[n] > 0.0f) collideNode(f, rho[n], om, p.zeroF0);
                        else if (p.zeroF0) f[0] = 0.0f;
                        for (int m = 0; m < kDirections; ++m) {
                            const int ti = i + kC[m][0], tj = j + kC[m][1], tk = k + kC[m][2];
                            if (ti < 1 || tj < 1 || tk < 1 || ti > g.dims.x - 2 || tj > g.dims.y - 2 || tk > g.dims.z - 2) continue;
                            b[g.index(ti, tj, tk) * kDirections + size_t(m)] = f[m];
                        }
                    }
            std::swap(a, b);
        }
        for (size_t n = 0; n < nodes; ++n) {
            double sum = 0.0;
            for (int m = 0; m < kDirections; ++m) sum += double(a[n * kDirections + size_t(m)]);
            out.rgb[n * 3 + size_t(c)] = float(sum) * p.intensity[c];
            if (!faces) continue;
            for (int face = 0; face < kFaces; ++face) {
                double e = 0.0;
                for (int m = 1; m < kDirections; ++m) {
                    const int* cm = kC[m];
                    const double dot = -(cm[0] * kFaceNormals[face][0] + cm[1] * kFaceNormals[face][1] + cm[2] * kFaceNormals[face][2]);
                    if (dot > 0.0) e += double(a[n * kDirections + size_t(m)]) * dot / std::sqrt(double(cm[0] * cm[0] + cm[1] * cm[1] + cm[2] * cm[2]));
                }
                (*faces)[(n * 3 + size_t(c)) * kFaces + size_t(face)] = float(e) * p.intensity[c];
            }
        }
    });
    return out;
}

// Trilinear sample of a per-node, per-channel face grid (solveSmall's faces) at p: [face] = RGB.
std::array<glm::vec3, kFaces> sampleFaces(const GridGeometry& g, const std::vector<float>& faces, const glm::dvec3& p)
{
    const glm::dvec3 u = glm::clamp((p - g.origin) / g.spacing, glm::dvec3(0.0), glm::dvec3(g.dims - 1));
    const glm::ivec3 i0 = glm::min(glm::ivec3(u), g.dims - 2);
    const glm::dvec3 f = u - glm::dvec3(i0);
    std::array<glm::vec3, kFaces> out{};
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const double w = (o.x ? f.x : 1.0 - f.x) * (o.y ? f.y : 1.0 - f.y) * (o.z ? f.z : 1.0 - f.z);
        const size_t n = g.index(i0.x + o.x, i0.y + o.y, i0.z + o.z);
        for (int ch = 0; ch < 3; ++ch)
            for (int face = 0; face < kFaces; ++face) out[size_t(face)][ch] += float(w * double(faces[(n * 3 + size_t(ch)) * kFaces + size_t(face)]));
    }
    return out;
}

// The lattice's density from the splatted optical depth per coarse step x (in density units: the mean
// fine density x the fine steps a coarse step crosses, summed over plants): the density whose one-step
// extinction equals the Beer-Lambert transmittance exp(-sigma_t x) of that depth, rho = (1 - exp(-sigma_t
// x)) / sigma_t, at most 1 (sigma_t: the largest channel's, so rho sigma_t <= 1 in every channel). It is
// the continuum limit of the fine steps' (1 - rho sigma_t)^m and lets more light through than that
// product of the mean density would, as clumped foliage does. A plain rho = x takes out x sigma_t per
// step: the stands' interiors came out about 1.4x too dark against per-instance solves (`sylva study
// scene`, docs/ACCURACY.md "Scene scale"); this mapping matched them to 0.01 on average.
DensityGrid densityOn(const GridGeometry& g, const std::vector<float>& depth, double sigmaT)
{
    DensityGrid d;
    d.geometry = g;
    d.density = depth;
    for (float& v : d.density)
        v = sigmaT > 0.0 ? float(std::min(1.0, -std::expm1(-sigmaT * double(v)) / sigmaT)) : std::min(v, 1.0f);
    return d;
}

double largestExtinction(const LbParams& p)
{
    double s = 0.0;
    for (const ChannelParams& c : p.channels) s = std::max(s, double(c.sigmaA) + double(c.sigmaS));
    return s;
}

// kAutoCellsPerCrown nodes across the median crown (its larger horizontal extent), within [4,
// kAutoMaxResolution].
int autoResolution(const std::vector<ForestPlant>& plants, const std::vector<ForestSpecies>& species, const glm::dvec3& extent)
{
    std::vector<double> crowns;
    for (const ForestPlant& p : plants) {
        const ForestSpecies& s = species[size_t(p.species)];
        if (s.biomass > 0.0) crowns.push_back(double(p.scale) * std::max(s.boxMax.x - s.boxMin.x, s.boxMax.z - s.boxMin.z));
    }
    std::nth_element(crowns.begin(), crowns.begin() + std::ptrdiff_t(crowns.size() / 2), crowns.end());
    const double crown = crowns[crowns.size() / 2];
    const double want = crown > 0.0 ? std::max(extent.x, extent.z) * kAutoCellsPerCrown / crown + 2.0 : 4.0;
    return int(std::clamp(std::ceil(want), 4.0, double(kAutoMaxResolution)));
}

} // namespace

ForestGridResult solveForestGrid(const std::vector<ForestPlant>& plants, const std::vector<ForestSpecies>& species,
                                 const LbParams& params, const ForestGridSettings& settings)
{
    const auto t0 = std::chrono::steady_clock::now();
    if (settings.resolution != kAutoResolution && (settings.resolution < 4 || settings.resolution > 512))
        throw Error("forest grid: resolution " + std::to_string(settings.resolution) + " is outside [4, 512] (0: automatic)");
    ForestGridResult r;
    r.factors.assign(plants.size(), glm::vec3(1.0f));
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const ForestPlant& p : plants) {
        if (p.species < 0 || size_t(p.species) >= species.size()) throw Error("forest grid: a plant's species index is out of range");
        if (!(p.scale > 0.0f) || !std::isfinite(p.scale)) throw Error("forest grid: a plant's scale must be finite and > 0");
        const ForestSpecies& s = species[size_t(p.species)];
        if (!(s.biomass > 0.0)) continue;
        lo = glm::min(lo, p.position + double(p.scale) * s.boxMin);
        hi = glm::max(hi, p.position + double(p.scale) * s.boxMax);
    }
    if (!(lo.x <= hi.x)) {   // no plant with biomass: nothing shades anything
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return r;
    }
    const glm::dvec3 extent = hi - lo;
    r.resolution = settings.resolution != kAutoResolution ? settings.resolution : autoResolution(plants, species, extent);
    const double h = std::max({extent.x, extent.z, 1e-6}) / double(r.resolution - 2);
    GridGeometry g;
    g.spacing = h;
    g.dims = glm::max(glm::ivec3(glm::ceil(extent / h)) + 3, glm::ivec3(3));
    g.origin = lo - h;   // one empty boundary layer (and a margin) around the plants
    r.geometry = g;
    r.density.assign(g.nodeCount(), 0.0f);
    std::vector<Box> boxes(plants.size());
    for (size_t i = 0; i < plants.size(); ++i) {
        const ForestSpecies& s = species[size_t(plants[i].species)];
        if (!(s.biomass > 0.0)) continue;
        boxes[i] = plantBox(plants[i], s);
        splat(boxes[i], g, r.density);
    }
    LbParams p = params;
    p.tolerance = 0.0;
    p.steps = 2 * g.longestEdge();
    p.stepsPerEdge = 2;
    r.steps = p.steps;
    const double sigmaT = largestExtinction(p);
    const DensityGrid forest = densityOn(g, r.density, sigmaT);
    r.density = forest.density;
    std::vector<float> forestFaces;
    r.lighting = g.nodeCount() <= kSmallNodes ? solveSmall(g, forest.density, p, p.steps, &forestFaces) : solveLighting(forest, p);
    r.faceFactors.assign(plants.size(), std::array<glm::vec3, kFaces>{});
    // Each plant alone on the same lattice (a local window around its box): the light its own crown leaves.
    tbb::parallel_for(size_t(0), plants.size(), [&](size_t i) {
        const ForestSpecies& s = species[size_t(plants[i].species)];
        if (!(s.biomass > 0.0)) return;
        const Box& b = boxes[i];
        // Two nodes beyond the box: the sample's stencil (nodes around the crown centre, possibly outside a
        // crown smaller than a cell) stays interior, where it holds the crown's shadow and scattered light
        // as in the forest grid, not the boundary condition.
        const glm::ivec3 n0 = glm::max(glm::ivec3(glm::floor((b.lo - g.origin) / h)) - 2, glm::ivec3(0));
        const glm::ivec3 n1 = glm::min(glm::ivec3(glm::ceil((b.hi - g.origin) / h)) + 2, g.dims - 1);
        GridGeometry lg;
        lg.spacing = h;
        lg.origin = g.origin + h * glm::dvec3(n0);
        lg.dims = glm::max(n1 - n0 + 1, glm::ivec3(3));
        std::vector<float> rho(lg.nodeCount(), 0.0f);
        splat(b, lg, rho);
        // The window's boundary layer stays empty (LB boundary nodes hold the boundary condition).
        for (int a = 0; a < lg.dims.x; ++a)
            for (int bb = 0; bb < lg.dims.y; ++bb)
                for (int c = 0; c < lg.dims.z; ++c)
                    if (a == 0 || bb == 0 || c == 0 || a == lg.dims.x - 1 || bb == lg.dims.y - 1 || c == lg.dims.z - 1)
                        rho[lg.index(a, bb, c)] = 0.0f;
        // Its window is small: 4 x its longest edge converges it (light crosses it four times), capped by the
        // forest grid's steps; an isolated plant still gets 1 (tst_forest_grid).
        LbParams pa = p;
        pa.steps = std::min(p.steps, 4 * lg.longestEdge());
        // Small windows (most, at forest resolutions) through the scalar loop, large ones through the solver.
        const DensityGrid ld = densityOn(lg, rho, sigmaT);
        const bool directions = !forestFaces.empty() && lg.nodeCount() <= kSmallNodes &&
                                std::max(b.hi.x - b.lo.x, b.hi.z - b.lo.z) >= kMinFaceCells * h;
        std::vector<float> aloneFaces;
        const LightingGrid alone = lg.nodeCount() <= 4096 || directions ? solveSmall(lg, ld.density, pa, pa.steps, directions ? &aloneFaces : nullptr)
                                                                         : solveLighting(ld, pa);
        const glm::dvec3 centre = 0.5 * (b.lo + b.hi);
        const glm::vec3 la = sample(alone, centre), lf = sample(r.lighting, centre);
        for (int c = 0; c < 3; ++c) r.factors[i][c] = la[c] > 0.0f ? lf[c] / la[c] : 1.0f;   // > 1 where neighbours scatter light in
        for (glm::vec3& f : r.faceFactors[i]) f = r.factors[i];
        if (!directions) return;
        const std::array<glm::vec3, kFaces> fa = sampleFaces(lg, aloneFaces, centre), ff = sampleFaces(g, forestFaces, centre);
        for (int face = 0; face < kFaces; ++face)
            for (int c = 0; c < 3; ++c) {
                const float a = fa[size_t(face)][c];
                // A face the plant alone leaves (nearly) unlit has no ratio to speak of: the plant's factor there.
                r.faceFactors[i][size_t(face)][c] = a > 1e-6f * la[c] ? std::min(ff[size_t(face)][c] / a, kMaxFaceFactor) : r.factors[i][c];
            }
    });
    r.minFactor = r.minFaceFactor = 1.0f;
    r.maxFactor = r.maxFaceFactor = 0.0f;
    std::vector<float> means;
    for (size_t i = 0; i < plants.size(); ++i) {
        const glm::vec3& f = r.factors[i];
        means.push_back((f.x + f.y + f.z) / 3.0f);
        for (int c = 0; c < 3; ++c) r.minFactor = std::min(r.minFactor, f[c]), r.maxFactor = std::max(r.maxFactor, f[c]);
        for (const glm::vec3& ff : r.faceFactors[i])
            for (int c = 0; c < 3; ++c) r.minFaceFactor = std::min(r.minFaceFactor, ff[c]), r.maxFaceFactor = std::max(r.maxFaceFactor, ff[c]);
    }
    if (r.factors.empty()) r.maxFactor = r.maxFaceFactor = 1.0f;
    if (!means.empty()) {
        std::nth_element(means.begin(), means.begin() + std::ptrdiff_t(means.size() / 2), means.end());
        r.medianFactor = means[means.size() / 2];
    }
    const float least = std::min(r.minFactor, r.minFaceFactor), most = std::max(r.maxFactor, r.maxFaceFactor);
    r.uniform = most <= 0.0f || (most - least) / most < settings.uniformSpread;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

LightingGrid solveGroundedLattice(const GridGeometry& g, std::vector<float> depth, const std::vector<uint8_t>& solid,
                                  const LbParams& params, int* stepsOut)
{
    const size_t nodes = g.nodeCount();
    if (depth.size() != nodes || solid.size() != nodes) throw Error("grounded lattice: the depth and solid arrays must have one value per node");
    const auto column = [&](int i, int k, int j) { return g.index(i, j, k); };
    // A column's foliage is a layer on its ground, far thinner than a node: all of its depth lies in the
    // column's first open node (split over two nodes, the lower one saw only what the upper one let through,
    // and a dense canopy's lower node went black). The top layer is always open.
    std::vector<int> firstOpen(size_t(g.dims.x) * size_t(g.dims.z), g.dims.y - 1);
    for (int i = 0; i < g.dims.x; ++i)
        for (int k = 0; k < g.dims.z; ++k) {
            int& open = firstOpen[size_t(i) * size_t(g.dims.z) + size_t(k)];
            for (int j = g.dims.y - 1; j >= 0 && !solid[column(i, k, j)]; --j) open = j;
            float sum = 0.0f;
            for (int j = 0; j < g.dims.y; ++j) sum += depth[column(i, k, j)], depth[column(i, k, j)] = 0.0f;
            depth[column(i, k, open)] = sum;
        }
    LbParams p = params;
    p.tolerance = 0.0;
    p.steps = 2 * g.longestEdge();
    if (stepsOut) *stepsOut = p.steps;
    // Outdoors nothing travels upward out of the ground: the boundary's directions that climb (the part of a
    // sun's lobe below the horizon) are dropped, as the ground beyond the lattice would absorb them. Then an
    // empty lattice over flat ground holds the boundary distribution at every open node (its sum the
    // unobstructed light), and a plant on open level ground gets 1.
    // The sun as a beam (the lobe's directions far from it cast terrain shadows the sun does not: on a gentle
    // ramp under a high sun the lobe's level directions lost 17% to the rising ground, tst_landscape_light);
    // a given boundary (a sky) as it is.
    std::vector<float> bc = p.boundary.empty() ? beamDistribution(p.sun) : p.boundary;
    for (int m = 0; m < kDirections; ++m)
        if (kC[m][1] > 0) bc[size_t(m)] = 0.0f;
    p.boundary = bc;
    // The canopy only takes light out: its extinction is all absorbed. A node hundreds of metres tall spreads a
    // canopy tens of metres thick over its height, diluting its sideways extinction by that ratio, so light it
    // scattered sideways stayed in the layer for the lattice's width: 1.45 x the unobstructed light inside a
    // dense stand (tst_landscape_light, before). Light plants scatter onto each other stays the species grids'
    // and the instances' forest grid's. A node's value is the light arriving at it (the distribution streamed
    // in, before its own collision): its own canopy's shading, which the species grids hold, is not in it.
    for (ChannelParams& c : p.channels) c.sigmaA += c.sigmaS, c.sigmaS = 0.0f;
    const DensityGrid d = densityOn(g, depth, largestExtinction(p));
    LightingGrid light = solveSmall(g, d.density, p, p.steps, nullptr, &solid);
    double freeSum = 0.0;
    for (int m = p.zeroF0 ? 1 : 0; m < kDirections; ++m) freeSum += double(bc[size_t(m)]);
    for (size_t n = 0; n < nodes; ++n)
        for (int c = 0; c < 3; ++c) {
            const double free = freeSum * double(p.intensity[c]);
            float& v = light.rgb[n * 3 + size_t(c)];
            v = free > 0.0 ? float(double(v) / free) : 1.0f;
        }
    // Every node of a column holds the light arriving at its canopy (its first open node): what a plant
    // anywhere in the column reads.
    for (int i = 0; i < g.dims.x; ++i)
        for (int k = 0; k < g.dims.z; ++k) {
            const size_t o = column(i, k, firstOpen[size_t(i) * size_t(g.dims.z) + size_t(k)]);
            const glm::vec3 v(light.rgb[o * 3], light.rgb[o * 3 + 1], light.rgb[o * 3 + 2]);
            for (int j = 0; j < g.dims.y; ++j)
                for (int c = 0; c < 3; ++c) light.rgb[column(i, k, j) * 3 + size_t(c)] = v[c];
        }
    return light;
}

std::string forestGridSummary(const ForestGridResult& r)
{
    char line[256];
    std::snprintf(line, sizeof line, "forest grid %d: %dx%dx%d (%.3g m), %d steps, %.3f s: factors %.3f / %.3f / %.3f (min / median / max), "
                  "per face %.3f-%.3f%s", r.resolution, r.geometry.dims.x, r.geometry.dims.y, r.geometry.dims.z, r.geometry.spacing, r.steps, r.seconds,
                  r.minFactor, r.medianFactor, r.maxFactor, r.minFaceFactor, r.maxFaceFactor, r.uniform ? " (exposure uniform)" : "");
    return line;
}

} // namespace sylva::lb
