// Monte Carlo reference solver: delta tracking through node-centred cells, track-length fluence per cell.
#include "core/reference/mc_reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_solver.h"

namespace sylva {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Per-path, per-cell track lengths are added to 64-bit integers in fixed point: integer addition is
// associative, so the totals do not depend on which thread traced which path (bit-identical results at
// any thread count). Resolution 2^-30 (sums) and 2^-24 (squares) of a node spacing.
constexpr double kSumScale = 1073741824.0;   // 2^30
constexpr double kSqScale = 16777216.0;      // 2^24

// Paths per parallel task and per progress report.
constexpr uint64_t kChunk = 1024;

// Safety stop for a single path (a medium that scatters without loss inside a huge grid); far beyond
// what any grid up to 512^3 needs.
constexpr uint64_t kMaxCollisionsPerPath = 100'000'000ull;

// Counter-based generator: the state of path p is a hash of (seed, stream, p), then SplitMix64 steps.
class PathRng {
public:
    PathRng(uint64_t seed, uint64_t stream, uint64_t path)
        : m_state(mix(mix(mix(seed ^ 0x5EED5EED5EED5EEDull) + stream * 0x9E3779B97F4A7C15ull) ^ (path * 0xD1B54A32D192ED03ull)))
    {
    }
    // Uniform in [0, 1), 53 bits.
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }

private:
    static uint64_t mix(uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    uint64_t next()
    {
        m_state += 0x9E3779B97F4A7C15ull;
        return mix(m_state);
    }
    uint64_t m_state;
};

// A unit vector orthonormal frame around n (Duff et al. 2017).
void frame(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b)
{
    const double s = std::copysign(1.0, n.z);
    const double a = -1.0 / (s + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + s * n.x * n.x * a, s * c, -s * n.x};
    b = {c, s + n.y * n.y * a, -n.y};
}

glm::dvec3 fromCosine(const glm::dvec3& u, double cosTheta, double phi)
{
    cosTheta = std::clamp(cosTheta, -1.0, 1.0);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    glm::dvec3 t, b;
    frame(u, t, b);
    return glm::normalize(sinTheta * std::cos(phi) * t + sinTheta * std::sin(phi) * b + cosTheta * u);
}

// New propagation direction after a Henyey-Greenstein scattering of light travelling along u: the
// cosine to u has density (1-g^2) / (2 (1 + g^2 - 2 g cos)^(3/2)); g > 0 forward. |g| = 1 is the delta limit.
glm::dvec3 sampleHg(const glm::dvec3& u, double g, PathRng& rng)
{
    const double xi = rng.uniform(), phi = 2.0 * kPi * rng.uniform();
    if (g >= 1.0) return u;
    if (g <= -1.0) return -u;
    double cosTheta;
    if (std::fabs(g) < 1e-4) {
        cosTheta = 1.0 - 2.0 * xi;
    } else {
        const double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
        cosTheta = (1.0 + g * g - q * q) / (2.0 * g);
    }
    return fromCosine(u, cosTheta, phi);
}

glm::dvec3 sampleIsotropic(PathRng& rng)
{
    const double z = 1.0 - 2.0 * rng.uniform(), phi = 2.0 * kPi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// One incident collimated beam: direction, and the cumulative choice of the box face it enters through.
struct Beam {
    glm::dvec3 dir;
    double power = 0.0;     // fluence x projected area of the domain (node units, unit intensity)
    double faceCdf[3]{};    // cumulative share of the power entering through the x, y, z faces
};

// One channel solve's medium and output accumulators.
struct Medium {
    glm::ivec3 n{0};
    glm::dvec3 lo{0.0}, hi{0.0};
    const float* density = nullptr;
    const float* wood = nullptr;   // may be null
    float brownThreshold = 0.5f;
    double sigmaT = 0.0, sigmaS = 0.0, g = 0.0, majorant = 0.0;
    bool absorb = true;            // zeroF0: sigma_a removes light; else it re-emits isotropically
    int maxBounces = -1;

    size_t cell(const glm::dvec3& p) const
    {
        const int i = std::clamp(int(std::floor(p.x + 0.5)), 0, n.x - 1);
        const int j = std::clamp(int(std::floor(p.y + 0.5)), 0, n.y - 1);
        const int k = std::clamp(int(std::floor(p.z + 0.5)), 0, n.z - 1);
        return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k);
    }
    // Distance from p (inside the domain) along u to the domain boundary.
    double exitDistance(const glm::dvec3& p, const glm::dvec3& u) const
    {
        double t = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a) {
            if (u[a] > 0.0) t = std::min(t, (hi[a] - p[a]) / u[a]);
            else if (u[a] < 0.0) t = std::min(t, (lo[a] - p[a]) / u[a]);
        }
        return std::max(0.0, t);
    }
};

// Per-thread scratch: this path's track length per cell, and the cells it touched.
struct Scratch {
    std::vector<float> track;
    std::vector<uint32_t> touched;
    uint64_t collisions = 0;
};

// Adds w * (length of the segment p + t u, t in [0, len], inside each cell) to the scratch (Amanatides-Woo).
void scoreSegment(const Medium& md, const glm::dvec3& p, const glm::dvec3& u, double len, double w, Scratch& s)
{
    if (!(len > 0.0) || !(w > 0.0)) return;
    int c[3], step[3];
    double tMax[3], tDelta[3];
    const int dims[3] = {md.n.x, md.n.y, md.n.z};
    for (int a = 0; a < 3; ++a) {
        c[a] = std::clamp(int(std::floor(p[a] + 0.5)), 0, dims[a] - 1);
        if (u[a] > 0.0) {
            step[a] = 1;
            tMax[a] = std::max(0.0, (double(c[a]) + 0.5 - p[a]) / u[a]);
            tDelta[a] = 1.0 / u[a];
        } else if (u[a] < 0.0) {
            step[a] = -1;
            tMax[a] = std::max(0.0, (double(c[a]) - 0.5 - p[a]) / u[a]);
            tDelta[a] = -1.0 / u[a];
        } else {
            step[a] = 0;
            tMax[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = std::numeric_limits<double>::infinity();
        }
    }
    double t = 0.0;
    for (;;) {
        const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        const double tNext = std::min(tMax[a], len);
        const float x = float(w * (tNext - t));
        if (x > 0.0f) {
            const size_t idx = (size_t(c[0]) * size_t(dims[1]) + size_t(c[1])) * size_t(dims[2]) + size_t(c[2]);
            if (s.track[idx] == 0.0f) s.touched.push_back(uint32_t(idx));
            s.track[idx] += x;
        }
        if (tMax[a] >= len) break;
        t = tNext;
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= dims[a]) break;
        tMax[a] += tDelta[a];
    }
}

// Traces one path from the sun side to its end, scoring into the scratch.
void tracePath(const Medium& md, const std::vector<Beam>& beams, const std::vector<double>& beamCdf, PathRng& rng,
               Scratch& s)
{
    // Beam, entry face (by projected area) and a uniform point on it.
    const double pick = rng.uniform() * beamCdf.back();
    size_t b = size_t(std::upper_bound(beamCdf.begin(), beamCdf.end(), pick) - beamCdf.begin());
    b = std::min(b, beams.size() - 1);
    const Beam& beam = beams[b];
    const double f = rng.uniform();
    const int face = f < beam.faceCdf[0] ? 0 : (f < beam.faceCdf[1] ? 1 : 2);
    glm::dvec3 p;
    for (int a = 0; a < 3; ++a) {
        const double r = rng.uniform();
        p[a] = a == face ? (beam.dir[a] > 0.0 ? md.lo[a] : md.hi[a]) : md.lo[a] + r * (md.hi[a] - md.lo[a]);
    }
    glm::dvec3 u = beam.dir;
    double w = 1.0;
    int bounces = 0;
    for (uint64_t guard = 0; guard < kMaxCollisionsPerPath; ++guard) {
        const double tExit = md.exitDistance(p, u);
        // Delta tracking: tentative collisions at the majorant rate, real with probability sigma_t rho / majorant.
        double t = 0.0;
        bool collided = false;
        size_t at = 0;
        if (md.majorant > 0.0) {
            for (;;) {
                t -= std::log(1.0 - rng.uniform()) / md.majorant;
                if (t >= tExit) break;
                at = md.cell(p + t * u);
                if (rng.uniform() * md.majorant < md.sigmaT * double(md.density[at])) {
                    collided = true;
                    break;
                }
            }
        }
        scoreSegment(md, p, u, collided ? t : tExit, w, s);
        if (!collided) return;
        p += t * u;
        ++s.collisions;
        if (md.maxBounces >= 0 && ++bounces > md.maxBounces) return;
        const bool brown = md.wood && md.wood[at] > md.brownThreshold;
        const double g = brown ? -1.0 : md.g;
        if (md.absorb) {
            // Implicit capture: the absorbed share sigma_a / sigma_t leaves; Russian roulette below 1/8.
            w *= md.sigmaS / md.sigmaT;
            if (!(w > 0.0)) return;
            if (w < 0.125) {
                if (rng.uniform() * 0.125 >= w) return;
                w = 0.125;
            }
            u = sampleHg(u, g, rng);
        } else {
            // f_0 kept: the absorbed share is re-emitted isotropically (LB: Omega_i0 = w_i).
            u = rng.uniform() * md.sigmaT < md.sigmaS ? sampleHg(u, g, rng) : sampleIsotropic(rng);
        }
    }
}

std::vector<Beam> incidentBeams(const lb::LbParams& params, Incidence incidence, const glm::dvec3& extent)
{
    const std::vector<float> bc = lb::boundaryOf(params);
    std::vector<std::pair<glm::dvec3, double>> dirs;   // direction, fluence at unit intensity
    if (incidence == Incidence::LatticeBeams) {
        for (int m = 1; m < lb::kDirections; ++m)
            if (bc[size_t(m)] > 0.0f)
                dirs.emplace_back(glm::normalize(glm::dvec3(lb::kC[m][0], lb::kC[m][1], lb::kC[m][2])), double(bc[size_t(m)]));
    } else {
        double total = 0.0;
        for (float v : bc) total += double(v);
        dirs.emplace_back(-glm::normalize(glm::dvec3(params.sun)), total);
    }
    const double area[3] = {extent.y * extent.z, extent.x * extent.z, extent.x * extent.y};
    std::vector<Beam> beams;
    for (const auto& [dir, fluence] : dirs) {
        Beam b;
        b.dir = dir;
        double proj[3], sum = 0.0;
        for (int a = 0; a < 3; ++a) sum += (proj[a] = area[a] * std::fabs(dir[a]));
        b.power = fluence * sum;
        b.faceCdf[0] = proj[0] / sum;
        b.faceCdf[1] = (proj[0] + proj[1]) / sum;
        b.faceCdf[2] = 1.0;
        beams.push_back(b);
    }
    return beams;
}

} // namespace

ReferenceResult solveReference(const DensityGrid& density, const lb::LbParams& params, const ReferenceSettings& settings,
                               Progress* progress)
{
    lb::validate(params);
    lb::validateDensity(density);
    if (settings.paths < 2 || settings.paths > kMaxReferencePaths)
        throw Error("invalid reference path count " + std::to_string(settings.paths) + ": must lie in [2, " +
                    std::to_string(kMaxReferencePaths) + "]");
    if (settings.maxBounces < -1) throw Error("invalid maximum bounce count: must be >= 0 (or -1 for unlimited)");
    const GridGeometry& geo = density.geometry;
    if (geo.nodeCount() > size_t(std::numeric_limits<uint32_t>::max()))
        throw Error("density grid too large for the reference solver (more than 2^32 nodes)");

    const auto t0 = std::chrono::steady_clock::now();
    ReferenceResult result;
    result.paths = settings.paths;
    result.mean.geometry = geo;
    result.mean.rgb.assign(geo.nodeCount() * 3, 0.0f);
    result.standardError.assign(geo.nodeCount() * 3, 0.0f);

    // Channels with equal optics share one solve (as in the LB solver); intensity only scales.
    int solveOf[3];
    std::vector<int> firstChannel;
    for (int c = 0; c < 3; ++c) {
        solveOf[c] = -1;
        const lb::ChannelParams& cp = params.channels[size_t(c)];
        for (size_t s = 0; s < firstChannel.size(); ++s) {
            const lb::ChannelParams& o = params.channels[size_t(firstChannel[s])];
            if (o.sigmaA == cp.sigmaA && o.sigmaS == cp.sigmaS && o.g == cp.g) solveOf[c] = int(s);
        }
        if (solveOf[c] < 0) {
            solveOf[c] = int(firstChannel.size());
            firstChannel.push_back(c);
        }
    }
    result.channelSolves = int(firstChannel.size());

    const glm::dvec3 extent(geo.dims);
    const std::vector<Beam> beams = incidentBeams(params, settings.incidence, extent);
    std::vector<double> beamCdf;
    double totalPower = 0.0;
    for (const Beam& b : beams) beamCdf.push_back(totalPower += b.power);

    float maxRho = 0.0f;
    for (float r : density.density) maxRho = std::max(maxRho, r);

    const size_t nodes = geo.nodeCount();
    std::vector<uint64_t> sum(nodes), sumSq(nodes);
    tbb::enumerable_thread_specific<Scratch> scratch([nodes] {
        Scratch s;
        s.track.assign(nodes, 0.0f);
        return s;
    });
    const uint64_t chunks = (settings.paths + kChunk - 1) / kChunk;
    const uint64_t chunksPerReport = std::max<uint64_t>(1, chunks / 200);
    double collisions = 0.0;

    for (size_t solve = 0; solve < firstChannel.size(); ++solve) {
        const int channel = firstChannel[solve];
        const lb::ChannelParams& cp = params.channels[size_t(channel)];
        Medium md;
        md.n = geo.dims;
        md.lo = glm::dvec3(-0.5);
        md.hi = extent - 0.5;
        md.density = density.density.data();
        md.wood = density.woodFraction.empty() ? nullptr : density.woodFraction.data();
        md.brownThreshold = params.brownThreshold;
        md.sigmaT = double(cp.sigmaA) + double(cp.sigmaS);
        md.sigmaS = double(cp.sigmaS);
        md.g = double(cp.g);
        md.majorant = md.sigmaT * double(maxRho);
        md.absorb = params.zeroF0;
        md.maxBounces = settings.maxBounces;
        std::fill(sum.begin(), sum.end(), 0);
        std::fill(sumSq.begin(), sumSq.end(), 0);
        for (Scratch& s : scratch) s.collisions = 0;

        auto runChunks = [&](uint64_t c0, uint64_t c1) {
            tbb::parallel_for(tbb::blocked_range<uint64_t>(c0, c1, 1), [&](const tbb::blocked_range<uint64_t>& r) {
                Scratch& s = scratch.local();
                for (uint64_t ch = r.begin(); ch != r.end(); ++ch) {
                    if (progress && progress->isCancelled()) return;
                    const uint64_t p1 = std::min(settings.paths, (ch + 1) * kChunk);
                    for (uint64_t path = ch * kChunk; path < p1; ++path) {
                        PathRng rng(settings.seed, uint64_t(channel), path);
                        tracePath(md, beams, beamCdf, rng, s);
                        for (uint32_t idx : s.touched) {
                            const double x = double(s.track[idx]);
                            s.track[idx] = 0.0f;
                            std::atomic_ref<uint64_t>(sum[idx]).fetch_add(uint64_t(x * kSumScale + 0.5), std::memory_order_relaxed);
                            std::atomic_ref<uint64_t>(sumSq[idx]).fetch_add(uint64_t(x * x * kSqScale + 0.5), std::memory_order_relaxed);
                        }
                        s.touched.clear();
                    }
                }
            });
        };
        for (uint64_t c0 = 0; c0 < chunks; c0 += chunksPerReport) {
            const uint64_t c1 = std::min(chunks, c0 + chunksPerReport);
            runChunks(c0, c1);
            if (progress) {
                const uint64_t done = std::min(settings.paths, c1 * kChunk);
                progress->report((double(solve) + double(done) / double(settings.paths)) / double(firstChannel.size()),
                                 "reference paths " + std::to_string(done) + "/" + std::to_string(settings.paths) +
                                     (firstChannel.size() > 1 ? " (channel solve " + std::to_string(solve + 1) + "/" +
                                                                    std::to_string(firstChannel.size()) + ")"
                                                              : ""));
            }
        }
        if (progress) progress->throwIfCancelled();
        uint64_t solveCollisions = 0;
        for (const Scratch& s : scratch) solveCollisions += s.collisions;
        collisions += double(solveCollisions) / double(settings.paths);

        // Fluence of a cell (volume 1) = total power x mean track length per path in the cell.
        const double n = double(settings.paths);
        for (int c = 0; c < 3; ++c) {
            if (solveOf[c] != int(solve)) continue;
            const double scale = totalPower * double(params.intensity[c]);
            for (size_t i = 0; i < nodes; ++i) {
                const double s1 = double(sum[i]) / kSumScale, s2 = double(sumSq[i]) / kSqScale;
                const double m = s1 / n;
                const double var = std::max(0.0, (s2 - s1 * m) / (n - 1.0));
                result.mean.rgb[i * 3 + size_t(c)] = float(scale * m);
                result.standardError[i * 3 + size_t(c)] = float(scale * std::sqrt(var / n));
            }
        }
    }
    result.collisionsPerPath = collisions / double(firstChannel.size());
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

double unobstructedValue(const lb::LbParams& params, int channel)
{
    double total = 0.0;
    for (float v : lb::boundaryOf(params)) total += double(v);
    return double(params.intensity[channel]) * total;
}

void normalizeToUnobstructed(LightingGrid& grid, const lb::LbParams& params, std::vector<float>* standardError)
{
    for (int c = 0; c < 3; ++c) {
        const double u = unobstructedValue(params, c);
        const double inv = u > 0.0 ? 1.0 / u : 0.0;
        for (size_t i = size_t(c); i < grid.rgb.size(); i += 3) grid.rgb[i] = float(double(grid.rgb[i]) * inv);
        if (standardError)
            for (size_t i = size_t(c); i < standardError->size(); i += 3) (*standardError)[i] = float(double((*standardError)[i]) * inv);
    }
}

namespace {

// Calls f(value index) for every interior node and every channel (or one channel when 0 <= channel < 3).
template <typename F>
void forInteriorValues(const GridGeometry& g, int channel, F&& f)
{
    const int c0 = channel >= 0 && channel < 3 ? channel : 0, c1 = channel >= 0 && channel < 3 ? channel + 1 : 3;
    for (int i = 1; i < g.dims.x - 1; ++i)
        for (int j = 1; j < g.dims.y - 1; ++j)
            for (int k = 1; k < g.dims.z - 1; ++k)
                for (int c = c0; c < c1; ++c) f(g.index(i, j, k) * 3 + size_t(c));
}

} // namespace

double relativeL2Interior(const LightingGrid& a, const LightingGrid& b, int channel)
{
    if (a.geometry.dims != b.geometry.dims || a.rgb.size() != b.rgb.size() || b.rgb.size() != b.geometry.nodeCount() * 3)
        throw Error("relativeL2Interior: the grids differ in size");
    double diff = 0.0, norm = 0.0;
    forInteriorValues(b.geometry, channel, [&](size_t i) {
        const double d = double(a.rgb[i]) - double(b.rgb[i]);
        diff += d * d;
        norm += double(b.rgb[i]) * double(b.rgb[i]);
    });
    return norm > 0.0 ? std::sqrt(diff / norm) : std::sqrt(diff);
}

double relativeNoiseInterior(const LightingGrid& ref, const std::vector<float>& standardError)
{
    if (standardError.size() != ref.rgb.size()) throw Error("relativeNoiseInterior: the standard errors differ in size");
    double var = 0.0, norm = 0.0;
    forInteriorValues(ref.geometry, -1, [&](size_t i) {
        var += double(standardError[i]) * double(standardError[i]);
        norm += double(ref.rgb[i]) * double(ref.rgb[i]);
    });
    return norm > 0.0 ? std::sqrt(var / norm) : std::sqrt(var);
}

} // namespace sylva
