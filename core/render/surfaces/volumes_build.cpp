// The volumes kind's builder: grids, bricks, lighting and temperatures into the flat arrays (once per set of
// assets), the placed instances camera-relative (per camera).
#include "core/render/scene_build.h"

#include <algorithm>

#include "core/base/error.h"

namespace sylva::scene_build {

std::vector<float> volumeBrickMaxima(const std::vector<float>& density, const glm::ivec3& dims, glm::ivec3* bricksOut)
{
    const int B = kVolumeBrick;
    const glm::ivec3 bricks = (dims + (B - 1)) / B;
    std::vector<float> out(size_t(bricks.x) * size_t(bricks.y) * size_t(bricks.z), 0.0f);
    for (int bx = 0; bx < bricks.x; ++bx)
        for (int by = 0; by < bricks.y; ++by)
            for (int bz = 0; bz < bricks.z; ++bz) {
                // Points in the brick, [b B - 0.5, (b + 1) B - 0.5), read nodes b B - 1 .. (b + 1) B.
                const glm::ivec3 b(bx, by, bz);
                const glm::ivec3 lo = glm::max(b * B - 1, glm::ivec3(0));
                const glm::ivec3 hi = glm::min(b * B + B, dims - 1);
                float m = 0.0f;
                for (int i = lo.x; i <= hi.x; ++i)
                    for (int j = lo.y; j <= hi.y; ++j)
                        for (int k = lo.z; k <= hi.z; ++k)
                            m = std::max(m, density[(size_t(i) * size_t(dims.y) + size_t(j)) * size_t(dims.z) + size_t(k)]);
                out[(size_t(bx) * size_t(bricks.y) + size_t(by)) * size_t(bricks.z) + size_t(bz)] = m;
            }
    if (bricksOut) *bricksOut = bricks;
    return out;
}

void buildVolumeGrids(RenderScene& rs, const Scene& scene)
{
    rs.volumeGrids.clear();
    rs.volumeDensity.clear();
    rs.volumeBricks.clear();
    rs.volumeLight.clear();
    rs.volumeTemperature.clear();
    rs.volumeBlackbody.clear();
    for (const VolumeDesc& vd : scene.volumes) {
        if (!vd.data) throw Error("volume '" + vd.name + "': its grid was not loaded");
        const VolumeData& d = *vd.data;
        const glm::ivec3 dims = d.density.geometry.dims;
        const size_t nodes = d.density.geometry.nodeCount();
        if (dims.x < 2 || dims.y < 2 || dims.z < 2 || d.density.density.size() != nodes)
            throw Error("volume '" + vd.name + "': the density grid needs at least 2 nodes per axis");
        VolumeGridRecord g{};
        g.dims = dims;
        g.densityOffset = uint32_t(rs.volumeDensity.size());
        for (float v : d.density.density) rs.volumeDensity.push_back(std::max(0.0f, v * vd.densityScale));
        std::vector<float> scaled(rs.volumeDensity.begin() + g.densityOffset, rs.volumeDensity.end());
        const std::vector<float> bricks = volumeBrickMaxima(scaled, dims, &g.bricks);
        g.brickOffset = uint32_t(rs.volumeBricks.size());
        rs.volumeBricks.insert(rs.volumeBricks.end(), bricks.begin(), bricks.end());
        for (int c = 0; c < 3; ++c) {
            const lb::ChannelParams& ch = vd.lighting.channels[size_t(c)];
            g.sigmaT[c] = ch.sigmaA + ch.sigmaS;
            g.sigmaS[c] = ch.sigmaS;
            g.g[c] = ch.g;
        }
        g.maxSigmaT = std::max({g.sigmaT.x, g.sigmaT.y, g.sigmaT.z, 1e-6f});
        g.lightOffset = kNoHit;
        if (!d.lighting.rgb.empty()) {
            if (d.lighting.geometry.dims != dims || d.lighting.rgb.size() != nodes * 3)
                throw Error("volume '" + vd.name + "': the lighting grid's dims differ from the density's");
            g.lightOffset = uint32_t(rs.volumeLight.size());   // in floats
            for (size_t n = 0; n < nodes; ++n)
                for (int c = 0; c < 3; ++c) {
                    const float norm = d.lightingNorm[c];
                    rs.volumeLight.push_back(norm > 0.0f ? d.lighting.rgb[n * 3 + size_t(c)] / norm : 0.0f);
                }
        }
        g.temperatureOffset = kNoHit;
        if (!d.temperature.empty()) {
            if (d.temperature.size() != nodes) throw Error("volume '" + vd.name + "': the temperature grid's dims differ from the density's");
            if (d.blackbody.size() != size_t(kVolumeBlackbodySize)) throw Error("volume '" + vd.name + "': no blackbody table");
            g.temperatureOffset = uint32_t(rs.volumeTemperature.size());
            rs.volumeTemperature.insert(rs.volumeTemperature.end(), d.temperature.begin(), d.temperature.end());
            if (rs.volumeBlackbody.empty()) rs.volumeBlackbody = d.blackbody;
        }
        g.tracer = uint32_t(vd.tracer);
        g.step = vd.step;
        g.shadowStep = vd.shadowStep;
        g.emission = std::exp2(vd.emissionExposure);
        rs.volumeGrids.push_back(g);
    }
}

void placeVolumes(RenderScene& rs, const Scene& scene, const glm::dvec3& eye)
{
    rs.volumeInstances.clear();
    for (size_t v = 0; v < scene.volumes.size(); ++v) {
        const VolumeDesc& vd = scene.volumes[v];
        if (!vd.data) throw Error("volume '" + vd.name + "': its grid was not loaded");
        const GridGeometry& gg = vd.data->density.geometry;
        for (const VolumePlacement& p : vd.instances) {
            // world = R (s x_grid) + p, x_grid = origin + spacing n  =>  n = (R^T (world - p) / s - origin) / spacing
            const double k = 1.0 / (double(p.scale) * gg.spacing);
            const glm::dmat3 m = glm::transpose(rotationDeg(p.rotationDeg)) * k;
            const glm::dvec3 t = -(m * (p.position - eye)) - gg.origin / gg.spacing;
            VolumeInstanceRecord r{};
            for (int i = 0; i < 3; ++i) r.row[i] = glm::vec4(float(m[0][i]), float(m[1][i]), float(m[2][i]), float(t[i]));
            r.grid = uint32_t(v);
            r.nodesPerMetre = float(k);
            rs.volumeInstances.push_back(r);
        }
    }
}

} // namespace sylva::scene_build
