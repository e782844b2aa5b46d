// The studio's frame through the renderer's one builder (buildSceneGeometry, the LB solves it triggers:
// frame_build.h lightFrame, then placeTopLevel).
#include "pipeline/render/view_frame.h"

#include <algorithm>
#include <cstdio>

#include "core/render/shade.h"
#include "core/render/trace.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/frame_build.h"

namespace sylva {

ViewFrame buildViewFrame(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance)
{
    Scene s = scene;
    s.render.accel = AccelKind::Bvh;   // the viewport traces BVHs
    ViewFrame f;
    f.rs = buildSceneGeometry(s, assets, LodLevels::All);
    lightFrame(f.rs, s);
    placeTopLevel(f.rs, s, sunRadiance, s.render.width, s.render.height, s.render.spp);
    return f;
}

namespace {

// A volume's optics and LB solve settings as text (equal text, equal solve).
std::string volumeOpticsText(const VolumeDesc& v)
{
    const lb::LbParams& p = v.lighting;
    char buf[96];
    std::snprintf(buf, sizeof buf, " %d %d %.9g %d %d %d", p.steps, p.stepsPerEdge, p.tolerance, int(p.storage), int(p.warmStart),
                  int(p.coarseStart));
    return opticsJsonMembers(p, v.preset) + buf;
}

} // namespace

bool sameVolumes(const std::vector<VolumeDesc>& a, const std::vector<VolumeDesc>& b)
{
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
        const VolumeDesc &x = a[i], &y = b[i];
        const bool places = x.instances.size() == y.instances.size() &&
                            std::equal(x.instances.begin(), x.instances.end(), y.instances.begin(), [](const VolumePlacement& p, const VolumePlacement& q) {
                                return p.position == q.position && p.rotationDeg == q.rotationDeg && p.scale == q.scale;
                            });
        if (x.name != y.name || x.grid != y.grid || x.temperature != y.temperature || x.preset != y.preset || x.lit != y.lit ||
            x.tracer != y.tracer || x.step != y.step || x.shadowStep != y.shadowStep || x.densityScale != y.densityScale ||
            x.emissionExposure != y.emissionExposure || !places || x.data != y.data ||
            volumeOpticsText(x) != volumeOpticsText(y))
            return false;
    }
    return true;
}


bool sameTerrainHeights(const TerrainDesc& a, const TerrainDesc& b)
{
    return a.dem == b.dem && a.field == b.field && a.origin == b.origin && a.spacing == b.spacing && a.heightScale == b.heightScale;
}

bool sameLandscapeTiles(const TerrainDesc& a, const TerrainDesc& b)
{
    const bool plants = a.tiles.plants.size() == b.tiles.plants.size() &&
                        std::equal(a.tiles.plants.begin(), a.tiles.plants.end(), b.tiles.plants.begin(), [](const TilePlantDesc& x, const TilePlantDesc& y) {
                            return x.species == y.species && x.speciesName == y.speciesName && x.spacing == y.spacing &&
                                   x.scaleMin == y.scaleMin && x.scaleMax == y.scaleMax;
                        });
    const bool set = a.tiling.set.size() == b.tiling.set.size() &&
                     std::equal(a.tiling.set.begin(), a.tiling.set.end(), b.tiling.set.begin(), [](const WangTile& x, const WangTile& y) {
                         return x.s == y.s && x.e == y.e && x.n == y.n && x.w == y.w;
                     });
    return a.cells == b.cells && a.tiles.size == b.tiles.size && a.tiles.seed == b.tiles.seed && plants &&
           a.tiling.horizontal == b.tiling.horizontal && a.tiling.vertical == b.tiling.vertical && a.tiling.setGiven == b.tiling.setGiven &&
           set && a.tiling.seed == b.tiling.seed;
}

bool sameLandscapeDensity(const TerrainDesc& a, const TerrainDesc& b)
{
    const DensityDesc &da = a.density, &db = b.density;
    return da.enabled == db.enabled && da.lower == db.lower && da.upper == db.upper && da.atLower == db.atLower &&
           da.atUpper == db.atUpper && da.a == db.a && da.m == db.m && da.noSnow == db.noSnow && da.noRock == db.noRock;
}

ViewFrameUpdate viewFrameUpdate(const Scene& built, const Scene& next)
{
    ViewFrameUpdate u;
    const SkyDesc &ka = built.skyModel, &kb = next.skyModel;
    // The sky's lights also follow the ground plane (setFrameSky: above the horizon only where it hides the rest).
    const bool sameSky = ka.kind == kb.kind && ka.built == kb.built && ka.lights == kb.lights && ka.interleave == kb.interleave &&
                         (!kb.analytic() || groundPlaneShown(built) == groundPlaneShown(next));
    u.rebuild = !sameTerrainHeights(built.terrain, next.terrain) || built.groups.size() != next.groups.size() || !sameSky ||
                built.render.accel != next.render.accel || built.render.leafTint != next.render.leafTint;
    if (u.rebuild) return u;
    u.landscape = !sameLandscapeTiles(built.terrain, next.terrain);
    u.density = !u.landscape && !sameLandscapeDensity(built.terrain, next.terrain);
    u.volumes = !sameVolumes(built.volumes, next.volumes);
    return u;
}

void updateViewFrame(ViewFrame& frame, const Scene& next, const ViewFrameUpdate& update)
{
    if (update.landscape) buildLandscapeArrays(frame.rs, next);
    else if (update.density) setLandscapeDensity(frame.rs, next);
    if (update.landscape || update.density) lightLandscape(frame.rs, next);   // which plants grow changed
    if (update.volumes) rebuildVolumeGrids(frame.rs, next);
}

bool viewFrameFits(const ViewFrame& frame, const Scene& scene) { return hasLevelsFor(frame.rs, scene); }

void placeViewFrame(ViewFrame& frame, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp)
{
    placeTopLevel(frame.rs, scene, sunRadiance, width, height, spp);
}

ViewPick pickViewFrame(const ViewFrame& frame, const glm::dvec3& placedAt, const CameraDesc& camera, int width, int height,
                       double x, double y)
{
    ViewPick out;
    if (width <= 0 || height <= 0 || frame.rs.frame.width <= 0) return out;
    RenderView v = frame.rs.view();
    v.camera = makeCamera(camera, width, height);
    v.width = width;
    v.height = height;
    Ray ray = cameraRay(v, float(x), float(y));
    ray.org = glm::vec3(camera.position - placedAt);   // the frame's origin is the eye it was placed for
    Hit hit{};
    if (!traceScene<false>(v, ray, hit)) return out;
    out.kind = hitKind(hit);
    if (out.kind == SurfaceKind::Instances && hit.inst != kNoHit) out.instance = int(hit.inst);
    out.distance = double(hit.t) * double(glm::length(ray.dir));
    out.point = placedAt + glm::dvec3(ray.org) + double(hit.t) * glm::dvec3(ray.dir);
    return out;
}

} // namespace sylva
