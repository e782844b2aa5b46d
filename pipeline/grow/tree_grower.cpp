// Procedural trees: a seeded branch skeleton per species, meshed as tapered tubes plus leaf cards to a triangle budget.
#include "pipeline/grow/tree_grower.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <mutex>

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/base/error.h"
#include "pipeline/grow/leaf_texture.h"

namespace sylva {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kGoldenAngle = 2.39996323f;  // radians
const glm::vec3 kUp(0.0f, 1.0f, 0.0f);

// splitmix64: a small, fully specified generator, so the same seed grows the same tree everywhere.
class Rng {
public:
    explicit Rng(uint64_t seed) : m_state(seed) {}
    uint64_t next()
    {
        uint64_t z = (m_state += 0x9E3779B97F4A7C15ULL);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        return z ^ (z >> 31);
    }
    float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }  // [0,1)
    float range(float lo, float hi) { return lo + (hi - lo) * uniform(); }
    float symmetric() { return 2.0f * uniform() - 1.0f; }  // [-1,1)
    glm::vec3 unitVector()
    {
        const float z = symmetric();
        const float phi = 2.0f * kPi * uniform();
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        return {r * std::cos(phi), z, r * std::sin(phi)};
    }

private:
    uint64_t m_state;
};

uint64_t mixSeed(uint64_t a, uint64_t b)
{
    Rng r(a ^ (b * 0xD1B54A32D192ED03ULL));
    return r.next();
}

glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback)
{
    const float len = glm::length(v);
    return len > 1e-12f ? v / len : fallback;
}

// Any unit vector perpendicular to unit vector t.
glm::vec3 perpendicular(const glm::vec3& t)
{
    const glm::vec3 ref = std::fabs(t.y) < 0.9f ? kUp : glm::vec3(1.0f, 0.0f, 0.0f);
    return glm::normalize(glm::cross(t, ref));
}

// ---- species descriptions -------------------------------------------------------------------

// How the branches of one level grow. Level 0 is the trunk (or a shrub's stems).
struct LevelSpec {
    int count;                // branches of this level on each parent (level 0: stems from the ground)
    float tStart, tEnd;       // attachment range along the parent, fractions of its length
    float angle, angleVar;    // degrees from the parent's direction (level 0: from +Y)
    float length, lengthVar;  // level 0: fraction of the height; else fraction of the parent's length
    float radius;             // level 0: fraction of the height; else fraction of the parent's radius there
    float taper;              // tip radius = (1 - taper) * base radius
    float curve;              // random bending over the branch, radians
    float tropism;            // bending toward +Y over the branch, radians (negative droops)
    int samples;              // path points
    int whorl;                // children per whorl (1 = spiral phyllotaxis)
    bool planar;              // children alternate left/right in a near-horizontal plane
};

enum class Envelope { Ellipsoid, Cone };

struct SpeciesSpec {
    float height;  // default height, metres
    int levels;    // branch levels including the trunk
    std::array<LevelSpec, 4> level;
    Envelope envelope;
    // Ellipsoid: centre height, vertical and horizontal radii. Cone: base height, apex height
    // above the base, radius at the base. Fractions of the default height.
    float envY, envRY, envRXZ;
    float leafFraction;  // share of the triangle budget that goes to leaf cards
    float leafArea;      // total leaf-card area / height^2 (constant over triangle budgets)
    int leafLevel;       // branches at this level or deeper bear leaves (and every terminal branch)
    float leafStart;     // leaves from this fraction of a bearing branch's length to its tip
    float leafTangent;   // leaf axis bias along the twig
    float leafUp;        // leaf axis bias toward +Y (negative hangs)
    float faceUp;        // card normal bias toward +Y
    float barkTile;      // bark texture tile size, fraction of the height
};

const SpeciesSpec& speciesSpec(TreeSpecies species)
{
    //                      count tStart tEnd angle var  length var  radius taper curve tropism samples whorl planar
    static const SpeciesSpec broadleaf{
        12.0f, 4,
        {{{1, 0, 0, 0, 4, 0.72f, 0, 0.022f, 0.7f, 0.25f, 0.1f, 12, 1, false},
          {9, 0.38f, 0.98f, 50, 15, 0.75f, 0.15f, 0.6f, 0.75f, 0.6f, 0.35f, 10, 1, false},
          {10, 0.2f, 0.97f, 45, 15, 0.45f, 0.25f, 0.55f, 0.75f, 0.7f, 0.2f, 7, 1, false},
          {9, 0.15f, 0.98f, 50, 20, 0.42f, 0.3f, 0.55f, 0.7f, 0.6f, 0.1f, 5, 1, false}}},
        Envelope::Ellipsoid, 0.6f, 0.4f, 0.4f,
        0.86f, 3.0f, 3, 0.2f, 0.6f, 0.3f, 0.8f, 0.04f};
    static const SpeciesSpec birch{
        16.0f, 4,
        {{{1, 0, 0, 0, 3, 0.95f, 0, 0.011f, 0.85f, 0.2f, 0.05f, 14, 1, false},
          {18, 0.3f, 0.97f, 40, 12, 0.4f, 0.2f, 0.45f, 0.8f, 0.5f, 0.2f, 9, 1, false},
          {8, 0.2f, 0.98f, 45, 15, 0.45f, 0.25f, 0.5f, 0.75f, 0.5f, -0.7f, 7, 1, false},
          {6, 0.2f, 0.98f, 35, 15, 0.55f, 0.3f, 0.55f, 0.7f, 0.4f, -1.6f, 6, 1, false}}},
        Envelope::Ellipsoid, 0.6f, 0.4f, 0.19f,
        0.85f, 1.3f, 3, 0.15f, 0.5f, -0.7f, 0.3f, 0.025f};
    static const SpeciesSpec conifer{
        20.0f, 3,
        {{{1, 0, 0, 0, 0.5f, 1.0f, 0, 0.016f, 0.92f, 0.02f, 0.1f, 16, 1, false},
          {100, 0.12f, 0.97f, 88, 8, 0.6f, 0.1f, 0.35f, 0.8f, 0.3f, -0.25f, 8, 5, false},
          {16, 0.1f, 0.95f, 55, 10, 0.35f, 0.2f, 0.5f, 0.7f, 0.3f, 0.05f, 5, 1, true},
          {}}},
        Envelope::Cone, 0.1f, 0.9f, 0.2f,
        0.8f, 2.0f, 1, 0.25f, 1.4f, 0.1f, 2.0f, 0.025f};
    static const SpeciesSpec shrub{
        2.0f, 3,
        {{{12, 0, 0, 16, 16, 0.95f, 0.15f, 0.012f, 0.75f, 0.7f, 0.0f, 8, 1, false},
          {8, 0.2f, 0.97f, 45, 15, 0.45f, 0.25f, 0.6f, 0.7f, 0.7f, 0.2f, 6, 1, false},
          {6, 0.2f, 0.98f, 45, 15, 0.45f, 0.3f, 0.6f, 0.7f, 0.6f, 0.1f, 5, 1, false},
          {}}},
        Envelope::Ellipsoid, 0.45f, 0.55f, 0.8f,
        0.84f, 8.0f, 2, 0.15f, 0.5f, 0.3f, 0.6f, 0.1f};
    switch (species) {
    case TreeSpecies::Broadleaf: return broadleaf;
    case TreeSpecies::Birch: return birch;
    case TreeSpecies::Conifer: return conifer;
    case TreeSpecies::Shrub: return shrub;
    }
    throw Error("species: unknown species value " + std::to_string(int(species)));
}

// ---- skeleton -------------------------------------------------------------------------------

struct Branch {
    uint32_t first = 0;  // first path point
    uint32_t count = 0;  // path points (>= 2)
    int level = 0;
    float length = 0;    // metres
    bool terminal = true;
};

// Branch paths as polylines, with smoothed tangents and radii per point. Metres.
struct Skeleton {
    std::vector<glm::vec3> points;
    std::vector<glm::vec3> tangents;
    std::vector<float> radii;
    std::vector<Branch> branches;

    struct Sample {
        glm::vec3 position, tangent;
        float radius;
    };
    Sample sample(const Branch& b, float t) const
    {
        const float f = std::clamp(t, 0.0f, 1.0f) * float(b.count - 1);
        const uint32_t i = std::min(uint32_t(f), b.count - 2);
        const float a = f - float(i);
        const uint32_t k = b.first + i;
        Sample s;
        s.position = points[k] + (points[k + 1] - points[k]) * a;
        s.tangent = safeNormalize(tangents[k] + (tangents[k + 1] - tangents[k]) * a, tangents[k]);
        s.radius = radii[k] + (radii[k + 1] - radii[k]) * a;
        return s;
    }
};

// The crown envelope, centred on a vertical axis through `axis` (x, z) at each height.
class CrownEnvelope {
public:
    explicit CrownEnvelope(const SpeciesSpec& spec) : m_spec(spec) {}

    // A single trunk carries the envelope with it, so a leaning trunk keeps its crown around it.
    void followTrunk(const std::vector<glm::vec3>& trunk) { m_trunk = trunk; }

    bool inside(const glm::vec3& p) const
    {
        const float h = m_spec.height;
        const float axisY = m_spec.envelope == Envelope::Ellipsoid ? m_spec.envY * h : p.y;
        const glm::vec2 axis = axisAt(axisY);
        const float x = p.x - axis.x, z = p.z - axis.y;
        if (m_spec.envelope == Envelope::Ellipsoid) {
            const float rx = m_spec.envRXZ * h, ry = m_spec.envRY * h;
            const float dy = (p.y - m_spec.envY * h) / ry;
            return (x * x + z * z) / (rx * rx) + dy * dy <= 1.0f;
        }
        const float base = m_spec.envY * h, apex = base + m_spec.envRY * h;
        if (p.y > apex) return false;
        const float r = m_spec.envRXZ * h * std::min(1.0f, (apex - p.y) / (apex - base));
        return x * x + z * z <= r * r;
    }

    // Distance along a straight ray from p to where it leaves the envelope, up to maxDistance.
    float exit(const glm::vec3& p, const glm::vec3& dir, float maxDistance) const
    {
        constexpr int kSteps = 48;
        const float step = maxDistance / kSteps;
        for (int k = 1; k <= kSteps; ++k)
            if (!inside(p + dir * (step * float(k)))) return step * float(k - 1);
        return maxDistance;
    }

private:
    glm::vec2 axisAt(float y) const
    {
        if (m_trunk.size() < 2) return glm::vec2(0.0f);
        if (y <= m_trunk.front().y) return glm::vec2(m_trunk.front().x, m_trunk.front().z);
        for (size_t i = 1; i < m_trunk.size(); ++i)
            if (m_trunk[i].y >= y) {
                const glm::vec3& a = m_trunk[i - 1];
                const glm::vec3& b = m_trunk[i];
                const float t = b.y > a.y ? (y - a.y) / (b.y - a.y) : 0.0f;
                return glm::vec2(a.x + (b.x - a.x) * t, a.z + (b.z - a.z) * t);
            }
        return glm::vec2(m_trunk.back().x, m_trunk.back().z);
    }

    const SpeciesSpec& m_spec;
    std::vector<glm::vec3> m_trunk;
};

class SkeletonBuilder {
public:
    SkeletonBuilder(const SpeciesSpec& spec, uint64_t seed) : m_spec(spec), m_envelope(spec), m_rng(seed) {}

    Skeleton build()
    {
        const LevelSpec& trunk = m_spec.level[0];
        const float h = m_spec.height;
        const float phase = m_rng.uniform() * 2.0f * kPi;
        for (int i = 0; i < trunk.count; ++i) {
            const float azimuth = phase + float(i) * kGoldenAngle + 0.3f * m_rng.symmetric();
            const glm::vec3 side(std::cos(azimuth), 0.0f, std::sin(azimuth));
            const float angle = glm::radians(trunk.angle + trunk.angleVar * m_rng.symmetric());
            const glm::vec3 dir = std::cos(angle) * kUp + std::sin(angle) * side;
            const glm::vec3 start = trunk.count > 1 ? side * (0.04f * h * std::sqrt((float(i) + 0.5f) / float(trunk.count)))
                                                    : glm::vec3(0.0f);
            float length = trunk.length * h * (1.0f + trunk.lengthVar * m_rng.symmetric());
            if (trunk.count > 1) length = std::max(std::min(length, 0.95f * m_envelope.exit(start, dir, length)), 0.3f * length);
            addBranch(0, start, dir, length, trunk.radius * h);
        }
        if (trunk.count == 1) m_envelope.followTrunk(m_skeleton.points);
        // Breadth first: m_skeleton.branches grows while we walk it.
        for (size_t b = 0; b < m_skeleton.branches.size(); ++b)
            if (m_skeleton.branches[b].level + 1 < m_spec.levels) addChildren(b);
        return std::move(m_skeleton);
    }

private:
    void addBranch(int level, const glm::vec3& start, const glm::vec3& direction, float length, float radius)
    {
        const LevelSpec& ls = m_spec.level[size_t(level)];
        Branch b;
        b.first = uint32_t(m_skeleton.points.size());
        b.count = uint32_t(ls.samples);
        b.level = level;
        b.length = length;
        const int steps = ls.samples - 1;
        const float seg = length / float(steps);
        // A steady bend in one random direction plus a little wobble, and tropism toward +Y.
        const glm::vec3 bendDir = safeNormalize(glm::cross(direction, m_rng.unitVector()), perpendicular(direction));
        const float bend = ls.curve / float(steps);
        const float lift = ls.tropism / float(steps);
        glm::vec3 p = start, d = direction;
        const float flareLength = 0.04f * m_spec.height;
        const float groundClearance = std::min(start.y, 0.02f * m_spec.height);
        for (int i = 0; i <= steps; ++i) {
            if (i > 0) {
                const glm::vec3 wobble = m_rng.unitVector() * (0.5f * bend);
                d = safeNormalize(d + bendDir * (bend * m_rng.range(0.5f, 1.5f)) + wobble + kUp * lift, d);
                if (p.y + d.y * seg < groundClearance) {
                    d.y = std::max(d.y, 0.3f);  // run along the ground rather than into it
                    d = glm::normalize(d);
                }
                p += d * seg;
            }
            const float t = float(i) / float(steps);
            float r = radius * (1.0f - ls.taper * t);
            if (level == 0) {
                const float f = std::max(0.0f, 1.0f - t * length / flareLength);
                r *= 1.0f + 0.5f * f * f;  // root flare
            }
            m_skeleton.points.push_back(p);
            m_skeleton.radii.push_back(r);
        }
        // Tangents: the average of the neighbouring segments.
        for (uint32_t i = 0; i < b.count; ++i) {
            const glm::vec3& a = m_skeleton.points[b.first + (i > 0 ? i - 1 : 0)];
            const glm::vec3& c = m_skeleton.points[b.first + std::min(i + 1, b.count - 1)];
            m_skeleton.tangents.push_back(safeNormalize(c - a, direction));
        }
        m_skeleton.branches.push_back(b);
    }

    void addChildren(size_t parentIndex)
    {
        const Branch parent = m_skeleton.branches[parentIndex];
        const LevelSpec& cs = m_spec.level[size_t(parent.level + 1)];
        if (cs.count <= 0) return;
        const float minRadius = 1.0e-4f * m_spec.height;
        const float minLength = 2.0e-3f * m_spec.height;
        const float phase = m_rng.uniform() * 2.0f * kPi;
        const int whorl = std::max(1, cs.whorl);
        const int whorls = (cs.count + whorl - 1) / whorl;
        for (int i = 0; i < cs.count; ++i) {
            float t, azimuth;
            if (whorl > 1) {
                const int w = i / whorl, k = i % whorl;
                t = cs.tStart + (cs.tEnd - cs.tStart) * (float(w) + 0.5f + 0.25f * m_rng.symmetric()) / float(whorls);
                azimuth = phase + float(w) * 0.7f + 2.0f * kPi * float(k) / float(whorl) + 0.25f * m_rng.symmetric();
            } else {
                t = cs.tStart + (cs.tEnd - cs.tStart) * (float(i) + 0.5f + 0.4f * m_rng.symmetric()) / float(cs.count);
                azimuth = cs.planar ? (i % 2 == 0 ? 0.0f : kPi) + 0.35f * m_rng.symmetric()
                                    : phase + float(i) * kGoldenAngle + 0.3f * m_rng.symmetric();
            }
            const Skeleton::Sample at = m_skeleton.sample(parent, t);
            glm::vec3 n;
            if (cs.planar) n = safeNormalize(glm::cross(kUp, at.tangent), perpendicular(at.tangent));
            else n = perpendicular(at.tangent);
            const glm::vec3 bn = glm::cross(at.tangent, n);
            const float angle = glm::radians(cs.angle + cs.angleVar * m_rng.symmetric());
            const glm::vec3 dir = safeNormalize(std::cos(angle) * at.tangent +
                                                    std::sin(angle) * (std::cos(azimuth) * n + std::sin(azimuth) * bn),
                                                at.tangent);
            const float nominal = cs.length * parent.length * (1.0f + cs.lengthVar * m_rng.symmetric());
            const float exit = m_envelope.exit(at.position, dir, nominal);
            const float length = std::max({std::min(nominal, 0.92f * exit), 0.03f * nominal, minLength});
            const float radius = std::max(std::min(cs.radius * at.radius, 0.9f * at.radius), minRadius);
            addBranch(parent.level + 1, at.position, dir, length, radius);
            m_skeleton.branches[parentIndex].terminal = false;
        }
    }

    const SpeciesSpec& m_spec;
    CrownEnvelope m_envelope;
    Rng m_rng;
    Skeleton m_skeleton;
};

// ---- bark tubes -----------------------------------------------------------------------------

// Tube resolution of one branch: `around` segments (0 = not meshed) and `rings` rings, then an apex.
struct TubeLod {
    uint32_t around = 0;
    uint32_t rings = 0;
    uint32_t vertices() const { return around ? (around + 1) * rings + 1 : 0; }
    uint32_t triangles() const { return around ? around * (2 * rings - 1) : 0; }
};

// Detail d is in segments per metre of circumference; larger d never gives fewer triangles.
TubeLod tubeLod(const Skeleton& sk, const Branch& b, double d)
{
    const double circumference = 2.0 * double(kPi) * double(sk.radii[b.first]);
    const double segments = circumference * d;
    TubeLod lod;
    if (b.level > 0 && segments < 2.5) return lod;
    const uint32_t maxAround = b.level == 0 ? 40 : 24;
    lod.around = uint32_t(std::clamp(std::lround(segments), 3L, long(maxAround)));
    const uint32_t maxRings = 2 * (b.count - 1);
    lod.rings = uint32_t(std::clamp(std::ceil(double(b.length) * d / 4.0), 1.0, double(maxRings)));
    return lod;
}

size_t woodTriangles(const Skeleton& sk, double d)
{
    size_t total = 0;
    for (const Branch& b : sk.branches) total += tubeLod(sk, b, d).triangles();
    return total;
}

// The largest detail whose wood fits the budget (the trunk is always meshed).
double chooseWoodDetail(const Skeleton& sk, size_t budget)
{
    double lo = 1e-3, hi = 1e5;
    if (woodTriangles(sk, hi) <= budget) return hi;
    for (int i = 0; i < 64; ++i) {
        const double mid = std::sqrt(lo * hi);
        if (woodTriangles(sk, mid) <= budget) lo = mid;
        else hi = mid;
    }
    return lo;
}

void emitTube(const Skeleton& sk, const Branch& b, const TubeLod& lod, float tile, TriangleMesh& mesh,
              uint32_t vertexOffset, size_t triangleOffset)
{
    const uint32_t s = lod.around, n = lod.rings;
    const float circumference = 2.0f * kPi * sk.radii[b.first];
    const float uRepeat = std::max(1.0f, std::round(circumference / tile));
    const float vScale = uRepeat / std::max(circumference, 1e-6f);  // keeps texels square at the base
    glm::vec3 normal = perpendicular(sk.tangents[b.first]);
    uint32_t v = vertexOffset;
    for (uint32_t k = 0; k < n; ++k) {
        const float t = float(k) / float(n);
        const Skeleton::Sample at = sk.sample(b, t);
        normal = safeNormalize(normal - at.tangent * glm::dot(normal, at.tangent), perpendicular(at.tangent));
        const glm::vec3 binormal = glm::cross(at.tangent, normal);
        for (uint32_t j = 0; j <= s; ++j) {
            const float theta = 2.0f * kPi * float(j % s) / float(s);
            const glm::vec3 radial = std::cos(theta) * normal + std::sin(theta) * binormal;
            mesh.positions[v] = at.position + radial * at.radius;
            if (b.level == 0) mesh.positions[v].y = std::max(mesh.positions[v].y, 0.0f);  // flat on the ground
            mesh.normals[v] = radial;
            mesh.uvs[v] = glm::vec2(uRepeat * float(j) / float(s), t * b.length * vScale);
            ++v;
        }
    }
    const Skeleton::Sample tip = sk.sample(b, 1.0f);
    const uint32_t apex = v;
    mesh.positions[apex] = tip.position;
    mesh.normals[apex] = tip.tangent;
    mesh.uvs[apex] = glm::vec2(0.5f * uRepeat, b.length * vScale);

    size_t f = triangleOffset;
    for (uint32_t k = 0; k + 1 < n; ++k) {
        const uint32_t r0 = vertexOffset + k * (s + 1), r1 = r0 + s + 1;
        for (uint32_t j = 0; j < s; ++j) {
            mesh.triangles[f++] = glm::uvec3(r0 + j, r0 + j + 1, r1 + j + 1);
            mesh.triangles[f++] = glm::uvec3(r0 + j, r1 + j + 1, r1 + j);
        }
    }
    const uint32_t last = vertexOffset + (n - 1) * (s + 1);
    for (uint32_t j = 0; j < s; ++j) mesh.triangles[f++] = glm::uvec3(last + j, last + j + 1, apex);
}

// ---- leaf cards -----------------------------------------------------------------------------

// Leaf-bearing stretches of the skeleton, laid end to end.
struct LeafBearers {
    std::vector<uint32_t> branch;
    std::vector<float> start;      // t where leaves begin on that branch
    std::vector<double> prefix;    // cumulative leafy length before each entry, metres
    double total = 0;
};

LeafBearers leafBearers(const Skeleton& sk, const SpeciesSpec& sp)
{
    LeafBearers lb;
    for (uint32_t i = 0; i < sk.branches.size(); ++i) {
        const Branch& b = sk.branches[i];
        if (!b.terminal && b.level < sp.leafLevel) continue;
        lb.branch.push_back(i);
        lb.start.push_back(sp.leafStart);
        lb.prefix.push_back(lb.total);
        lb.total += double(b.length) * double(1.0f - sp.leafStart);
    }
    return lb;
}

void emitLeaf(const Skeleton& sk, const SpeciesSpec& sp, const LeafBearers& lb, uint64_t leafSeed, size_t leaf,
              size_t leafCount, float cardSize, TriangleMesh& mesh, uint32_t vertexOffset, size_t triangleOffset)
{
    Rng rng(mixSeed(leafSeed, leaf));
    // Evenly spaced along the leafy stretches, jittered.
    const double along = (double(leaf) + double(rng.uniform())) / double(leafCount) * lb.total;
    const size_t e = size_t(std::upper_bound(lb.prefix.begin(), lb.prefix.end(), along) - lb.prefix.begin()) - 1;
    const Branch& b = sk.branches[lb.branch[e]];
    const float leafyLength = b.length * (1.0f - lb.start[e]);
    const float t = lb.start[e] + (1.0f - lb.start[e]) * float(std::clamp((along - lb.prefix[e]) / double(leafyLength), 0.0, 1.0));
    const Skeleton::Sample at = sk.sample(b, t);

    const float size = cardSize * rng.range(0.8f, 1.2f);
    const glm::vec3 outward = safeNormalize(glm::vec3(at.position.x, 0.0f, at.position.z), glm::vec3(0.0f));
    const glm::vec3 axis = safeNormalize(rng.unitVector() + at.tangent * sp.leafTangent + kUp * sp.leafUp + outward * 0.3f,
                                         at.tangent);
    const glm::vec3 facing = safeNormalize(rng.unitVector() + kUp * sp.faceUp, kUp);
    glm::vec3 across = glm::cross(axis, facing);
    across = glm::length(across) > 1e-4f ? glm::normalize(across) : perpendicular(axis);
    const glm::vec3 normal = glm::cross(across, axis);
    const glm::vec3 jitter = rng.unitVector();
    const glm::vec3 scatter = (jitter - at.tangent * glm::dot(jitter, at.tangent)) * (0.5f * size);
    const glm::vec3 base = at.position + scatter - axis * (0.08f * size);

    std::array<glm::vec3, 4> corner = {base - across * (0.5f * size), base + across * (0.5f * size),
                                       base + across * (0.5f * size) + axis * size,
                                       base - across * (0.5f * size) + axis * size};
    float lowest = corner[0].y;
    for (const glm::vec3& c : corner) lowest = std::min(lowest, c.y);
    if (lowest < 0.0f)
        for (glm::vec3& c : corner) c.y -= lowest;  // nothing below the ground
    static constexpr std::array<glm::vec2, 4> kUv = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)};
    for (uint32_t c = 0; c < 4; ++c) {
        mesh.positions[vertexOffset + c] = corner[c];
        mesh.normals[vertexOffset + c] = normal;
        mesh.uvs[vertexOffset + c] = kUv[c];
    }
    mesh.triangles[triangleOffset] = glm::uvec3(vertexOffset, vertexOffset + 1, vertexOffset + 2);
    mesh.triangles[triangleOffset + 1] = glm::uvec3(vertexOffset, vertexOffset + 2, vertexOffset + 3);
}

// Runs f(i) for i in [0, n) in fixed blocks, so each element takes the same code path at any thread count.
template <class F>
void forEachBlocked(size_t n, size_t block, const F& f)
{
    const size_t blocks = (n + block - 1) / block;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, blocks, 1),
        [&](const tbb::blocked_range<size_t>& r) {
            for (size_t bl = r.begin(); bl != r.end(); ++bl)
                for (size_t i = bl * block, end = std::min(n, (bl + 1) * block); i < end; ++i) f(i);
        },
        tbb::simple_partitioner());
}

// The textures depend on the species only: drawn once per process.
struct SpeciesTextures {
    std::once_flag once;
    ImageRgba leaf, bark;
};

const SpeciesTextures& speciesTextures(TreeSpecies species)
{
    static std::array<SpeciesTextures, 4> cache;
    SpeciesTextures& entry = cache.at(size_t(species));
    std::call_once(entry.once, [&] {
        // Isolated, so a thread waiting inside cannot pick up another growTree and re-enter call_once.
        tbb::this_task_arena::isolate([&] {
            entry.leaf = makeLeafTexture(species);
            entry.bark = makeBarkTexture(species);
        });
    });
    return entry;
}

void report(Progress* progress, double fraction, const char* message)
{
    if (progress) progress->report(fraction, message);
}

} // namespace

bool parseSpecies(const std::string& name, TreeSpecies* out)
{
    std::string lower = name;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    static constexpr TreeSpecies kAll[] = {TreeSpecies::Broadleaf, TreeSpecies::Birch, TreeSpecies::Conifer,
                                           TreeSpecies::Shrub};
    for (TreeSpecies s : kAll)
        if (lower == speciesName(s)) {
            if (out) *out = s;
            return true;
        }
    return false;
}

TreeSpecies speciesFromName(const std::string& name)
{
    TreeSpecies s{};
    if (parseSpecies(name, &s)) return s;
    std::string known;
    for (const std::string& n : speciesNames()) known += (known.empty() ? "" : ", ") + n;
    throw Error("species: unknown species '" + name + "' (known: " + known + ")");
}

std::string speciesName(TreeSpecies species)
{
    switch (species) {
    case TreeSpecies::Broadleaf: return "broadleaf";
    case TreeSpecies::Birch: return "birch";
    case TreeSpecies::Conifer: return "conifer";
    case TreeSpecies::Shrub: return "shrub";
    }
    return "unknown";
}

std::vector<std::string> speciesNames() { return {"broadleaf", "birch", "conifer", "shrub"}; }

float defaultTreeHeight(TreeSpecies species) { return speciesSpec(species).height; }

GrownTree growTree(const GrowOptions& options, Progress* progress)
{
    const SpeciesSpec& spec = speciesSpec(options.species);  // throws on a bad enum value
    if (options.targetTriangles < kMinGrowTriangles || options.targetTriangles > kMaxGrowTriangles)
        throw Error("targetTriangles: " + std::to_string(options.targetTriangles) + " is outside [" +
                    std::to_string(kMinGrowTriangles) + ", " + std::to_string(kMaxGrowTriangles) + "]");
    if (!(options.height == 0.0f || (options.height >= 0.1f && options.height <= 150.0f)))
        throw Error("height: " + std::to_string(options.height) + " m is outside [0.1, 150] (0 = species default)");

    report(progress, 0.0, "growing the branch skeleton");
    const uint64_t speciesSalt = uint64_t(options.species) + 1;
    Skeleton sk = SkeletonBuilder(spec, mixSeed(options.seed, speciesSalt)).build();

    // Scale so the top of the skeleton sits at the requested height.
    float top = 0;
    for (const glm::vec3& p : sk.points) top = std::max(top, p.y);
    const float height = options.height > 0 ? options.height : spec.height;
    const float scale = height / std::max(top, 1e-3f);
    for (glm::vec3& p : sk.points) p *= scale;
    for (float& r : sk.radii) r *= scale;
    for (Branch& b : sk.branches) b.length *= scale;

    // Budget: wood first (as fine as its share allows), leaf cards take the rest.
    const size_t target = options.targetTriangles;
    const size_t woodBudget = size_t(double(target) * double(1.0f - spec.leafFraction));
    const double detail = chooseWoodDetail(sk, woodBudget);
    std::vector<TubeLod> lods(sk.branches.size());
    std::vector<uint32_t> vertexOffset(sk.branches.size() + 1, 0);
    std::vector<size_t> triangleOffset(sk.branches.size() + 1, 0);
    for (size_t i = 0; i < sk.branches.size(); ++i) {
        lods[i] = tubeLod(sk, sk.branches[i], detail);
        vertexOffset[i + 1] = vertexOffset[i] + lods[i].vertices();
        triangleOffset[i + 1] = triangleOffset[i] + lods[i].triangles();
    }
    const size_t woodTris = triangleOffset.back();
    const uint32_t woodVerts = vertexOffset.back();
    const size_t leafCount = (target - woodTris) / 2;

    GrownTree tree;
    TriangleMesh& mesh = tree.mesh;
    const size_t vertexCount = size_t(woodVerts) + 4 * leafCount;
    const size_t triangleCount = woodTris + 2 * leafCount;
    mesh.positions.resize(vertexCount);
    mesh.normals.resize(vertexCount);
    mesh.uvs.resize(vertexCount);
    mesh.triangles.resize(triangleCount);
    mesh.triangleMaterial.assign(triangleCount, 1u);
    std::fill(mesh.triangleMaterial.begin(), mesh.triangleMaterial.begin() + std::ptrdiff_t(woodTris), 0u);

    Material bark;
    bark.name = "bark";
    bark.isLeaf = false;
    bark.diffuse = glm::vec3(1.0f);  // the texture carries the colour
    Material leaf;
    leaf.name = "leaf";
    leaf.isLeaf = true;
    leaf.diffuse = glm::vec3(1.0f);
    mesh.materials = {bark, leaf};

    report(progress, 0.2, "meshing the bark");
    const float tile = spec.barkTile * height;
    forEachBlocked(sk.branches.size(), 16, [&](size_t i) {
        if (lods[i].around) emitTube(sk, sk.branches[i], lods[i], tile, mesh, vertexOffset[i], triangleOffset[i]);
    });

    report(progress, 0.45, "placing the leaves");
    const LeafBearers bearers = leafBearers(sk, spec);
    const float leafArea = spec.leafArea * height * height;
    const float cardSize = std::sqrt(leafArea / float(std::max<size_t>(leafCount, 1)));
    const uint64_t leafSeed = mixSeed(options.seed, speciesSalt + 0x1EAF);
    forEachBlocked(leafCount, 4096, [&](size_t i) {
        emitLeaf(sk, spec, bearers, leafSeed, i, leafCount, cardSize, mesh, woodVerts + uint32_t(4 * i),
                 woodTris + 2 * i);
    });

    report(progress, 0.8, "drawing the textures");
    const SpeciesTextures& textures = speciesTextures(options.species);
    tree.leafTexture = textures.leaf;
    tree.barkTexture = textures.bark;
    report(progress, 1.0, "grown");
    return tree;
}

} // namespace sylva
