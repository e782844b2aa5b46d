// The scene file's volumes: optics preset with per-channel overrides, grid files, tracer, placements.
// Geist & Westall in the docs = Geist & Westall, "Lattice-Boltzmann Lighting Models".
#include "pipeline/scene/scene_volumes.h"

#include <cmath>
#include <set>

#include "core/base/error.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/scene/scene_species.h"
#include "pipeline/scene/summary_text.h"

namespace sylva {

using json::above;
using json::Bounds;
using json::JsonReader;
using json::JsonWriter;
using json::KeyPath;
using json::Layout;
using json::Table;
using json::TableBuilder;

VolumeDesc defaultVolume()
{
    VolumeDesc d;
    volumePreset(d.preset, &d.lighting);
    d.lighting.stepsPerEdge = 2;
    d.lighting.storage = lb::Storage::Fp16;
    return d;
}

namespace {

SceneReadContext& in(JsonReader& r) { return static_cast<SceneReadContext&>(r); }
SceneWriteContext& out(JsonWriter& w) { return static_cast<SceneWriteContext&>(w); }

const Table<VolumePlacement>& placementTable()
{
    static const Table<VolumePlacement> table = [] {
        TableBuilder<VolumePlacement> b(Layout::Inline);
        b.vector("position", &VolumePlacement::position).doc("`[x, y, z]`", "world metres of the grid frame's origin");
        b.custom(
             "rotation",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, VolumePlacement& i) {
                 if (v.isDouble()) i.rotationDeg = glm::vec3(0.0f, r.floatNumber(v, p), 0.0f);
                 else if (v.isArray()) i.rotationDeg = r.vec3(v, p);
                 else r.wrongType(v, p, "[rx, ry, rz] or a number (degrees about +Y)");
             },
             [](JsonWriter& w, const VolumePlacement& i, const KeyPath& p, int) { w.vector3(i.rotationDeg, p); })
            .doc("`[rx, ry, rz]` or number", "degrees, X then Y then Z; a number is degrees about +Y")
            .shown("[0, 0, 0]");
        b.number("scale", &VolumePlacement::scale, above(0.0)).doc("number", "uniform, > 0");
        return b.table;
    }();
    return table;
}

} // namespace

const Table<VolumeDesc>& volumeTable()
{
    static const Table<VolumeDesc> table = [] {
        TableBuilder<VolumeDesc> b(Layout::Block, defaultVolume());
        b.custom(
             "name",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, VolumeDesc& d) {
                 d.name = r.string(v, p).toStdString();
                 if (d.name.empty()) r.fail(p, "must not be empty");
             },
             [](JsonWriter& w, const VolumeDesc& d, const KeyPath&, int) { w.string(d.name); })
            .doc("string", "non-empty, unique among volumes")
            .required("missing (required)")
            .shown("required");
        b.custom(
             "grid", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, VolumeDesc& d) { d.grid = readFilePath(in(r), v, p, "a grid file"); },
             [](JsonWriter& w, const VolumeDesc& d, const KeyPath&, int) { w.string(storedMeshPath(d.grid, out(w).base)); })
            .doc("string", "density grid: `.npy` (with its sidecar: origin, spacing) or `.vdb` (grid `density`), relative to the scene file")
            .required("missing (required: a density grid file)")
            .shown("required");
        b.custom(
             "temperature",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, VolumeDesc& d) { d.temperature = readFilePath(in(r), v, p, "a grid file"); },
             [](JsonWriter& w, const VolumeDesc& d, const KeyPath&, int) { w.string(storedMeshPath(d.temperature, out(w).base)); })
            .doc("string", "temperature grid in kelvin (same dims; its values as a density grid's): blackbody emission; optional")
            .writtenIf([](const VolumeDesc& d) { return !d.temperature.empty(); })
            .shown("none");
        b.custom(
             "preset",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, VolumeDesc& d) {
                 if (!v.isUndefined()) d.preset = r.string(v, p).toStdString();
                 const lb::LbParams keep = d.lighting;
                 if (!volumePreset(d.preset, &d.lighting)) r.fail(p, "unknown volume preset '" + d.preset + "' (known: cloud, smoke, pmma)");
                 d.lighting.stepsPerEdge = keep.stepsPerEdge;
                 d.lighting.storage = keep.storage;
             },
             [](JsonWriter& w, const VolumeDesc& d, const KeyPath&, int) { w.string(d.preset); })
            .doc("string", "optics: `cloud` (Geist & Westall: sigma_a 0.008, sigma_s 0.792, g 0.9), `smoke` (0.25, 0.25, 0.3), `pmma`")
            .readWhenAbsent = true;
        channelsField(b, "sigma_a", &lb::ChannelParams::sigmaA)
            .doc("number or `[r, g, b]`", "absorption per node spacing at density 1; one number sets all channels")
            .shown("preset's");
        channelsField(b, "sigma_s", &lb::ChannelParams::sigmaS).doc("number or `[r, g, b]`", "scattering per node spacing at density 1").shown("preset's");
        channelsField(b, "g", &lb::ChannelParams::g).doc("number or `[r, g, b]`", "Henyey-Greenstein asymmetry, -1 .. 1").shown("preset's");
        b.number("density_scale", &VolumeDesc::densityScale, above(0.0))
            .doc("number", "> 0: multiplies the grid's densities (the product must stay in [0, 1])");
        b.enumeration(
             "tracer", &VolumeDesc::tracer, [](const std::string& s, VolumeTracer* t) { return parseVolumeTracer(s, t); },
             [](VolumeTracer t) { return volumeTracerName(t); }, "volume tracer", "lb, single, combined")
            .doc("string",
                 "`lb` (Geist & Westall: the LB solution along the ray), `single` (sun single scattering, a shadow march per "
                 "step), `combined` (single + the LB's multiple scattering); ACCURACY.md \"Volumes\"");
        b.number("step", &VolumeDesc::step, Bounds{.lo = 0.05, .hi = 16.0, .unit = " nodes"})
            .doc("number", "largest camera-ray step in nodes, 0.05 .. 16 (adaptive: at most optical depth 0.25 a step, down to step / 8)");
        b.number("shadow_step", &VolumeDesc::shadowStep, Bounds{.lo = 0.05, .hi = 16.0, .unit = " nodes"})
            .doc("number", "shadow-march step in nodes, 0.05 .. 16 (cloud shadows, single scattering)");
        b.number("emission_exposure", &VolumeDesc::emissionExposure, Bounds{.lo = -64.0, .hi = 64.0, .unit = " stops"})
            .doc("number", "stops: emission = 2^this x sigma_a x density x Planck(T) / luminance(Planck(6500 K)), -64 .. 64");
        b.integer("steps_per_edge", [](auto& d) -> auto& { return d.lighting.stepsPerEdge; }, (long long)lb::kStepsPerEdge.lo,
                  (long long)lb::kStepsPerEdge.hi)
            .doc("integer", "LB steps per node of the longest edge, " + json::spanText(lb::kStepsPerEdge) + " (2 = the seed's count)");
        b.array("instances", &VolumeDesc::instances, placementTable(), "a volume needs at least one placement")
            .doc("object", "placements of the grid, at least one");
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& p, VolumeDesc& d) {
            for (const auto& c : d.lighting.channels) {
                if (!(c.sigmaA >= 0.0f) || !(c.sigmaS >= 0.0f)) r.fail(p, "sigma_a and sigma_s must be >= 0");
                if (!(c.sigmaA + c.sigmaS > 0.0f)) r.fail(p, "sigma_a + sigma_s must be > 0 (a medium that does nothing)");
                if (!(c.g >= -1.0f && c.g <= 1.0f)) r.fail(p, "g must lie in [-1, 1]");
            }
            d.lit = d.tracer != VolumeTracer::Single;
        };
        return b.table;
    }();
    return table;
}

std::string describeVolumes(const Scene& scene)
{
    std::string s;
    for (const VolumeDesc& v : scene.volumes)
        s += "volume " + v.name + ": " + v.grid + ", " + v.preset + ", tracer " + volumeTracerName(v.tracer) + ", " +
             std::to_string(v.instances.size()) + (v.instances.size() == 1 ? " placement\n" : " placements\n");
    return s;
}

namespace {

std::vector<float> checkedValues(const std::string& volume, const std::string& path, const DensityGrid& g, float scale, float hi,
                                 const char* what)
{
    const glm::ivec3 d = g.geometry.dims;
    if (d.x < 2 || d.y < 2 || d.z < 2 || g.density.empty())
        throw Error("volume '" + volume + "': " + path + ": a grid needs at least 2 nodes per axis");
    std::vector<float> v(g.density.size());
    for (size_t i = 0; i < v.size(); ++i) {
        const float x = g.density[i] * scale;
        if (!std::isfinite(x) || x < 0.0f || x > hi) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "node %zu holds %g; %s must be finite and in [0, %g]", i, double(x), what, double(hi));
            throw Error("volume '" + volume + "': " + path + ": " + msg);
        }
        v[i] = x;
    }
    return v;
}

} // namespace

void loadSceneVolumes(Scene& scene)
{
    std::set<std::string> names;
    for (VolumeDesc& v : scene.volumes) {
        if (!names.insert(v.name).second) throw Error("volumes: the name '" + v.name + "' is used twice");
        auto data = std::make_shared<VolumeData>();
        DensityGrid g = readDensityFile(v.grid);
        data->density.geometry = g.geometry;
        data->density.density = checkedValues(v.name, v.grid, g, v.densityScale, 1.0f, "density x density_scale");
        data->density.woodFraction.assign(data->density.density.size(), 0.0f);
        if (!v.temperature.empty()) {
            const DensityGrid t = readDensityFile(v.temperature);
            if (t.geometry.dims != g.geometry.dims)
                throw Error("volume '" + v.name + "': " + v.temperature + ": the temperature grid's dims differ from the density grid's");
            data->temperature = checkedValues(v.name, v.temperature, t, 1.0f, 1e6f, "a temperature");
        }
        v.data = std::move(data);
    }
}

} // namespace sylva
