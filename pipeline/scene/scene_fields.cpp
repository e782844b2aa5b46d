// The scene file's field table: each key once, with its type, bounds, default (from the records of
// core/scene/scene.h), a one-line doc (docs/SCENE.md's rule column) and its words in `sylva info`.
// The docs cite papers by short name: Geist & Steele = "A Lighting Model for Fast Rendering of Forest
// Ecosystems"; Geist & Westall = "Lattice-Boltzmann Lighting Models"; Dietrich et al. = Dietrich,
// Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly Complex Plant Populations".
#include "pipeline/scene/scene_fields.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/base/error.h"
#include "core/sky/preetham.h"
#include "core/sky/sun_position.h"
#include "core/sky/virtual_lights.h"
#include "core/terrain/height_field.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/render/display_view.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/scene/scene_species.h"
#include "pipeline/scene/scene_volumes.h"
#include "pipeline/scene/summary_text.h"

namespace sylva {

using json::above;
using json::atLeast;
using json::Bounds;
using json::JsonReader;
using json::JsonWriter;
using json::KeyPath;
using json::Layout;
using json::Table;
using json::TableBuilder;

namespace {

SceneReadContext& in(JsonReader& r) { return static_cast<SceneReadContext&>(r); }
SceneWriteContext& out(JsonWriter& w) { return static_cast<SceneWriteContext&>(w); }

// A seed's rule in the docs: "0 .. 2^62" (kMaxSeed, core/base/param_spec.h).
std::string seedRule() { return "0 .. " + paramNumber(double(kMaxSeed)); }
const float kNoUpperBound = std::numeric_limits<float>::max();

const Table<GrowSpec>& growTable()
{
    static const Table<GrowSpec> table = [] {
        TableBuilder<GrowSpec> b(Layout::Inline);
        b.custom(
             "species",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, GrowSpec& g) { g.species = readGrowerSpecies(in(r), v, p); },
             [](JsonWriter& w, const GrowSpec& g, const KeyPath&, int) { w.string(g.species); })
            .doc("string", "`broadleaf`, `birch`, `conifer`, `shrub` (any case; stored lower-case)");
        b.integer("seed", &GrowSpec::seed, 0, (long long)kMaxSeed).doc("integer", seedRule());
        b.integer("triangles", &GrowSpec::triangles, (long long)kMinGrowTriangles, (long long)kMaxGrowTriangles)
            .doc("integer", "1000 .. 1000000");
        b.number("height", &GrowSpec::height, Bounds{.lo = 0.1, .hi = 150.0, .unit = " metres", .orZero = " (the species' default)"})
            .doc("number", "metres; 0 = the species' default, else 0.1 .. 150");
        return b.table;
    }();
    return table;
}

// Over the species: the preset and grid live beside the LB parameters.
const Table<SpeciesDesc>& lightingTable()
{
    static const Table<SpeciesDesc> table = [] {
        TableBuilder<SpeciesDesc> b(Layout::Inline, defaultSpecies());
        b.custom(
             "preset", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) { readLightingPreset(in(r), v, p, d); },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath&, int) { w.string(d.preset); })
            .doc("string", "`leaf`, `dogrose`, `cloud`, `pmma` (LB_MODEL.md presets)")
            .readWhenAbsent = true;   // first: the overrides below apply to the preset's parameters
        channelsField(b, "sigma_a", &lb::ChannelParams::sigmaA)
            .doc("number or `[r, g, b]`", "absorption per lattice step; one number sets all channels").shown("preset's");
        channelsField(b, "sigma_s", &lb::ChannelParams::sigmaS)
            .doc("number or `[r, g, b]`", "scattering per lattice step").shown("preset's");
        channelsField(b, "g", &lb::ChannelParams::g)
            .doc("number or `[r, g, b]`", "Henyey-Greenstein asymmetry").shown("preset's");
        b.boolean("zero_f0", [](auto& d) -> auto& { return d.lighting.zeroF0; })
            .doc("bool", "`true` for plants (zero f_0 each step), `false` keeps absorbed light (clouds, plastics)")
            .shown("preset's");
        b.param(kSpeciesGrid, &SpeciesDesc::grid);
        b.boolean("solid", [](auto& d) -> auto& { return d.solid; })
            .doc("bool",
                 "`true`: the mesh is voxelized as a solid (interior filled by winding numbers, open edges do not leak; "
                 "plastics such as the PMMA teapot), `false` (default): its surface, as plants")
            .writtenIf([](const SpeciesDesc& d) { return d.solid; });
        b.boolean("lb", [](auto& d) -> auto& { return d.lit; })
            .doc("bool",
                 "`false`: no LB grid is solved; the species is lit conventionally, its ambient term the diffuse colour x the "
                 "sun's radiance (the LB's value in open space; Geist & Westall, Figure 5), default `true`")
            .writtenIf([](const SpeciesDesc& d) { return !d.lit; });
        b.custom(
             "steps",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) {
                 // A step count (0: steps_per_edge x the longest edge) asks for fixed steps.
                 d.lighting.steps = int(r.integer(v, p, 0, 1000000));
                 d.lighting.tolerance = 0.0;
             },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath&, int) { w.integer((long long)d.lighting.steps); })
            .doc("integer", "fixed step count, 0 .. 1000000; 0 = `steps_per_edge` x the longest grid edge");
        b.integer("steps_per_edge", [](auto& d) -> auto& { return d.lighting.stepsPerEdge; }, (long long)lb::kStepsPerEdge.lo,
                  (long long)lb::kStepsPerEdge.hi)
            .doc("integer",
                 json::spanText(lb::kStepsPerEdge) + ": with `steps` 0, steps per node of the longest edge (2 = the seed's count). The default 1 is the cheapest "
                 "solve at its error on the measured fronts ([ACCURACY.md](ACCURACY.md)): the LB's transport error against Monte "
                 "Carlo (5-11%) dwarfs the under-0.7% the seed's 2 x or a tolerance would change");
        b.number("tolerance", [](auto& d) -> auto& { return d.lighting.tolerance; }, atLeast(0.0, " (0: fixed step count)"))
            .doc("number",
                 "> 0: solve until the relative change per step falls below it (checked about every 16 steps, at most 4 x the "
                 "longest edge); 0: fixed steps; excludes `steps` > 0");
        b.custom(
             "fp16",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) {
                 d.lighting.storage = r.boolean(v, p) ? lb::Storage::Fp16 : lb::Storage::Fp32;
             },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath&, int) { w.boolean(d.lighting.storage == lb::Storage::Fp16); })
            .doc("bool",
                 "store the distributions in half precision (changes the error against the reference by under 3e-4, half the "
                 "memory, 0.6-0.8x the time at grids 64-128; false: fp32)");
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& p, SpeciesDesc& d) { checkLighting(in(r), p, d); };
        return b.table;
    }();
    return table;
}

const Table<SpeciesDesc>& speciesTable()
{
    static const Table<SpeciesDesc> table = [] {
        TableBuilder<SpeciesDesc> b(Layout::Block, defaultSpecies());
        b.custom(
             "name", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) { readSpeciesName(in(r), v, p, d); },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath&, int) { w.string(d.name); })
            .doc("string", "non-empty, unique among species")
            .required("missing (required)")
            .shown("required")
            .thenCheck([](JsonReader& r, const QJsonObject& o, const KeyPath& p, SpeciesDesc&) { checkMeshOrGrow(in(r), o, p); });
        b.custom(
             "mesh", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) { d.meshPath = readMeshPath(in(r), v, p); },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath& p, int) { writeMeshPath(out(w), d, p); })
            .doc("string",
                 "mesh file (any format the importer reads); relative paths start at the scene file's folder; must exist and be a "
                 "regular file")
            .shown("-")
            .writtenIf([](const SpeciesDesc& d) { return !d.grow; });
        b.optionalObject("grow", &SpeciesDesc::grow, growTable())
            .doc("object", "a procedural tree (`sylva grow`); give `mesh` or `grow`, not both")
            .shown("-");
        b.custom(
             "leaf_materials",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, SpeciesDesc& d) { readLeafMaterials(in(r), v, p, d); },
             [](JsonWriter& w, const SpeciesDesc& d, const KeyPath&, int) { writeLeafMaterials(w, d); })
            .doc("array of strings", "material names that are leaves (overrides the importer's leaf/wood split)");
        b.object("lighting", [](auto& d) -> auto& { return d; }, lightingTable())
            .doc("object", "LB lighting of the species' grid")
            .shown("{}");
        return b.table;
    }();
    return table;
}

const Table<InstanceDesc>& instanceTable()
{
    static const Table<InstanceDesc> table = [] {
        TableBuilder<InstanceDesc> b(Layout::Inline);
        b.custom(
             "species", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, InstanceDesc& i) { readInstanceSpecies(in(r), v, p, i); },
             [](JsonWriter& w, const InstanceDesc& i, const KeyPath& p, int) { writeInstanceSpecies(out(w), i, p); })
            .doc("string", "name of a declared species")
            .required("missing (required: the name of a species)")
            .shown("required");
        b.vector("position", &InstanceDesc::position)
            .doc("`[x, y, z]`", "metres (read as doubles)")
            .required("missing (required)")
            .shown("required");
        b.custom(
             "rotation", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, InstanceDesc& i) { readRotation(in(r), v, p, i); },
             [](JsonWriter& w, const InstanceDesc& i, const KeyPath& p, int) { writeRotation(out(w), i, p); })
            .doc("`[rx, ry, rz]` or number", "degrees, applied X, then Y, then Z; a number is degrees about +Y")
            .shown("[0, 0, 0]");
        b.number("scale", &InstanceDesc::scale, above(0.0)).doc("number", "uniform, > 0");
        b.boolean("on_terrain", &InstanceDesc::onTerrain)
            .doc("bool", "`position`'s y is the height above the terrain's surface at its x, z (needs a `terrain`); false: world y")
            .writtenIf([](const InstanceDesc& d) { return d.onTerrain; });
        return b.table;
    }();
    return table;
}

const Table<GroundDesc>& groundTable()
{
    static const Table<GroundDesc> table = [] {
        TableBuilder<GroundDesc> b(Layout::Inline);
        b.boolean("enabled", &GroundDesc::enabled).doc("bool", "a ground plane").summarized([](const GroundDesc& g) {
            return std::string(g.enabled ? "plane" : "none");
        });
        b.number("height", &GroundDesc::height)
            .doc("number", "world y of the plane, metres")
            .summarized([](const GroundDesc& g) { return g.enabled ? " at y = " + human(g.height) + " m" : std::string(); }, true);
        b.color("color", &GroundDesc::color, 0.0f, 1.0f).doc("`[r, g, b]`", "albedo, each in [0, 1]").summarized([](const GroundDesc& g) {
            return g.enabled ? "albedo " + human3(g.color) : std::string();
        });
        return b.table;
    }();
    return table;
}

const Table<TilePlantDesc>& tilePlantTable()
{
    static const Table<TilePlantDesc> table = [] {
        TableBuilder<TilePlantDesc> b(Layout::Inline);
        b.custom(
             "species",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, TilePlantDesc& t) {
                 InstanceDesc probe;
                 readInstanceSpecies(in(r), v, p, probe);   // unknown names refused with the declared ones
                 t.species = probe.species;
                 t.speciesName = r.string(v, p).toStdString();
             },
             [](JsonWriter& w, const TilePlantDesc& t, const KeyPath& p, int) {
                 InstanceDesc probe;
                 probe.species = t.species;
                 writeInstanceSpecies(out(w), probe, p);
             })
            .doc("string", "name of a declared species")
            .required("missing (required: the name of a species)")
            .shown("required");
        b.number("spacing", &TilePlantDesc::spacing, above(0.0))
            .doc("number", "metres between roots of this species (Poisson disk; between two species the mean of their spacings), > 0");
        b.number("scale_min", &TilePlantDesc::scaleMin, above(0.0)).doc("number", "uniform scale drawn in [scale_min, scale_max], > 0");
        b.number("scale_max", &TilePlantDesc::scaleMax, above(0.0)).doc("number", ">= scale_min");
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& p, TilePlantDesc& t) {
            if (t.scaleMax < t.scaleMin) r.fail(p.field("scale_max"), "must be >= scale_min (" + json::fmt(t.scaleMin) + ")");
        };
        return b.table;
    }();
    return table;
}

const Table<TileSetDesc>& tileSetTable()
{
    static const Table<TileSetDesc> table = [] {
        TableBuilder<TileSetDesc> b(Layout::Block);
        b.number("size", &TileSetDesc::size, above(0.0)).doc("number", "metres, the side of a tile (its frame; mapped onto a cell scaled by cell / size), > 0");
        b.integer("seed", &TileSetDesc::seed, 0, (long long)kMaxSeed).doc("integer", seedRule() + "; the populations (splitmix64, as the scatter tool)");
        b.array("plants", &TileSetDesc::plants, tilePlantTable(), "a tile set needs at least one species")
            .doc("object", "the species of every tile's population, drawn in this order");
        return b.table;
    }();
    return table;
}

const Table<TilingDesc>& tilingTable()
{
    static const Table<TilingDesc> table = [] {
        TableBuilder<TilingDesc> b(Layout::Inline);
        b.custom(
             "colors",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, TilingDesc& t) {
                 const QJsonArray a = r.array(v, p);
                 if (a.size() != 2) r.fail(p, "must be [horizontal, vertical] (two integers)");
                 t.horizontal = int(r.integer(a.at(0), p.at(0), 1, 16));
                 t.vertical = int(r.integer(a.at(1), p.at(1), 1, 16));
             },
             [](JsonWriter& w, const TilingDesc& t, const KeyPath&, int) {
                 w.raw("[");
                 w.integer((long long)t.horizontal);
                 w.raw(", ");
                 w.integer((long long)t.vertical);
                 w.raw("]");
             })
            .doc("`[h, v]`", "edge colours: h for south/north edges, v for east/west edges, 1 .. 16 each");
        b.custom(
             "set",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, TilingDesc& t) {
                 const QJsonArray a = r.array(v, p);
                 t.setGiven = true;
                 t.set.clear();
                 for (qsizetype i = 0; i < a.size(); ++i) {
                     const QJsonArray e = r.array(a.at(i), p.at(i));
                     if (e.size() != 4) r.fail(p.at(i), "must be [south, east, north, west] (four colours)");
                     WangTile w;
                     w.s = int(r.integer(e.at(0), p.at(i).at(0), 0, 15));
                     w.e = int(r.integer(e.at(1), p.at(i).at(1), 0, 15));
                     w.n = int(r.integer(e.at(2), p.at(i).at(2), 0, 15));
                     w.w = int(r.integer(e.at(3), p.at(i).at(3), 0, 15));
                     t.set.push_back(w);
                 }
             },
             [](JsonWriter& w, const TilingDesc& t, const KeyPath&, int) {
                 w.raw("[");
                 for (size_t i = 0; i < t.set.size(); ++i) {
                     const WangTile& x = t.set[i];
                     w.raw(i ? ", [" : "[");
                     w.raw(std::to_string(x.s) + ", " + std::to_string(x.e) + ", " + std::to_string(x.n) + ", " + std::to_string(x.w) + "]");
                 }
                 w.raw("]");
             })
            .doc("array of `[s, e, n, w]`",
                 "the Wang tiles' edge colours (south, east, north, west); absent: every combination (h^2 v^2 tiles). Refused when "
                 "empty or when it cannot tile (a south/west pair its tiles' north/east colours meet has no tile)")
            .shown("every combination")
            .writtenIf([](const TilingDesc& t) { return t.setGiven; });
        b.integer("seed", &TilingDesc::seed, 0, (long long)kMaxSeed)
            .doc("integer", seedRule() + "; which matching tile each cell takes (a hash of seed and cell)");
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& p, TilingDesc& t) {
            try {
                (void)wangTileSet(t);
            } catch (const Error& e) {
                r.fail(p.field("set"), e.what());
            }
        };
        return b.table;
    }();
    return table;
}

const Table<DensityDesc>& densityTable()
{
    static const Table<DensityDesc> table = [] {
        TableBuilder<DensityDesc> b(Layout::Inline);
        b.boolean("enabled", &DensityDesc::enabled).doc("bool", "thin the plants by altitude (Dietrich et al., eq. 2, 3) and the ground's colour");
        b.number("lower", &DensityDesc::lower).doc("number", "world y of the lower tree line, metres");
        b.number("upper", &DensityDesc::upper).doc("number", "world y of the upper tree line, metres (>= lower)");
        b.number("at_lower", &DensityDesc::atLower, Bounds{.lo = 0.0, .hi = 1.0}).doc("number", "d_min: density threshold at and below the lower line, [0, 1]");
        b.number("at_upper", &DensityDesc::atUpper, Bounds{.lo = 0.0, .hi = 1.0}).doc("number", "d_max: at and above the upper line, [0, 1]");
        b.integer("a", &DensityDesc::a, 1, 1 << 20).doc("integer", "eq. 2's multiplier (p = (a (id_inst + id_tile) mod m) / (m - 1))");
        b.integer("m", &DensityDesc::m, 2, 1 << 20).doc("integer", "eq. 2's modulus, >= 2");
        b.boolean("no_snow", &DensityDesc::noSnow).doc("bool", "no plants where the ground is snow (above `snow_line`)");
        b.boolean("no_rock", &DensityDesc::noRock).doc("bool", "no plants where the ground is rock (steeper than `rock_slope`)");
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& p, DensityDesc& d) {
            if (d.upper < d.lower) r.fail(p.field("upper"), "must be >= lower (" + json::fmt(d.lower) + ")");
        };
        return b.table;
    }();
    return table;
}

// An optional nested object of the terrain, read when present, written when `when` holds.
template <class U, class Get>
void terrainObject(TableBuilder<TerrainDesc>& b, const char* key, Get get, const Table<U>& sub, bool (*when)(const TerrainDesc&), const char* rule)
{
    json::Field<TerrainDesc>& f = b.custom(
        key, [get, &sub](JsonReader& r, const QJsonValue& v, const KeyPath& p, TerrainDesc& t) { readObject(r, r.object(v, p), p, get(t), sub); },
        [get, &sub](JsonWriter& w, const TerrainDesc& t, const KeyPath& p, int indent) { writeObject(w, get(const_cast<TerrainDesc&>(t)), p, sub, indent); });
    f.writeIf = when;
    f.nested = true;
    f.children = [&sub](std::vector<json::FieldRow>& o, const std::string& path) { documentFields(sub, path, o); };
    f.doc("object", rule).shown("");
}

const Table<TerrainDesc>& terrainTable()
{
    static const Table<TerrainDesc> table = [] {
        TableBuilder<TerrainDesc> b(Layout::Block);
        b.custom(
             "dem", [](JsonReader& r, const QJsonValue& v, const KeyPath& p, TerrainDesc& t) { t.dem = readFilePath(in(r), v, p, "a DEM image"); },
             [](JsonWriter& w, const TerrainDesc& t, const KeyPath&, int) { w.string(storedMeshPath(t.dem, out(w).base)); })
            .doc("string",
                 "elevation image (16-bit PNG, 8-bit image, float TIFF or EXR; first channel); relative paths start at the scene "
                 "file's folder")
            .required("missing (required: the elevation image)")
            .shown("required")
            .summarized([](const TerrainDesc& t) { return t.dem; });
        b.vector("origin", &TerrainDesc::origin)
            .doc("`[x, y, z]`", "world position of the DEM's first sample (row 0, column 0), metres; rows run along +z, columns along +x")
            .summarized([](const TerrainDesc& t) { return "origin " + human3(t.origin); });
        b.number("spacing", &TerrainDesc::spacing, above(0.0)).doc("number", "metres between samples, > 0").summarized([](const TerrainDesc& t) {
            return human(t.spacing) + " m spacing";
        });
        b.number("height_scale", &TerrainDesc::heightScale, above(0.0))
            .doc("number", "metres per DEM unit (the stored integer of integer images, the value of float ones), > 0")
            .summarized([](const TerrainDesc& t) { return human(t.heightScale) + " m per unit"; });
        b.color("rock_color", &TerrainDesc::rock, 0.0f, 1.0f).doc("`[r, g, b]`", "albedo of slopes steeper than `rock_slope`, each in [0, 1]");
        b.color("snow_color", &TerrainDesc::snow, 0.0f, 1.0f).doc("`[r, g, b]`", "albedo above `snow_line`, each in [0, 1]");
        b.number("rock_slope", &TerrainDesc::rockSlope, Bounds{.lo = 0.0, .hi = 90.0, .unit = " degrees"})
            .doc("number", "degrees from horizontal, [0, 90]; gentler slopes take `ground.color`");
        b.number("snow_line", &TerrainDesc::snowLine, atLeast(0.0, " (metres; 0 = no snow)"))
            .doc("number", "world y above which the ground is snow, metres; 0 = no snow");
        b.integer("cells", &TerrainDesc::cells, 0, 65536)
            .doc("integer",
                 "plant cells along the terrain's longer side (Dietrich et al.: 64 .. 512), each carrying a Wang tile of `tiles`; 0 = no plant "
                 "tiles; `sylva render --cells` overrides it")
            .writtenIf([](const TerrainDesc& t) { return t.cells > 0; })
            .summarized([](const TerrainDesc& t) { return t.cells > 0 ? std::to_string(t.cells) + " cells a side" : std::string(); });
        terrainObject(b, "tiles", [](TerrainDesc& t) -> TileSetDesc& { return t.tiles; }, tileSetTable(),
                      [](const TerrainDesc& t) { return t.cells > 0; }, "the tiles' plant population (required with `cells` > 0)");
        terrainObject(b, "tiling", [](TerrainDesc& t) -> TilingDesc& { return t.tiling; }, tilingTable(),
                      [](const TerrainDesc& t) { return t.cells > 0; }, "the Wang tile set and the tiling of the cells");
        terrainObject(b, "density", [](TerrainDesc& t) -> DensityDesc& { return t.density; }, densityTable(),
                      [](const TerrainDesc& t) { return t.density.enabled; }, "adaptive plant density while tracing (Dietrich et al., section 4.3)");
        b.table.after = [](JsonReader& r, const QJsonObject& o, const KeyPath& p, TerrainDesc& t) {
            if (t.cells > 0 && !o.contains(QLatin1String("tiles"))) r.fail(p.field("tiles"), "missing (required with cells > 0: the tiles' plants)");
        };
        return b.table;
    }();
    return table;
}

const Table<SunDesc>& sunTable()
{
    static const Bounds elevationBounds{.lo = -90.0, .hi = 90.0, .unit = " degrees"};
    static const Table<SunDesc> table = [] {
        TableBuilder<SunDesc> b(Layout::Inline);
        b.vector("direction", &SunDesc::direction, true)
            .doc("`[x, y, z]`", "toward the sun, any length (non-zero)")
            .writtenIf([](const SunDesc& s) { return !s.place.has_value(); })
            .summarized([](const SunDesc& s) {
                const glm::dvec3 sun(s.direction);   // elevation and azimuth in double
                const double len = glm::length(sun);
                const double elevation = len > 0.0 ? std::asin(std::clamp(sun.y / len, -1.0, 1.0)) * 180.0 / M_PI : 0.0;
                const double azimuth = std::atan2(sun.x, sun.z) * 180.0 / M_PI;
                char buf[160];
                std::snprintf(buf, sizeof buf, " (elevation %.1f deg, azimuth %.1f deg)", elevation, azimuth < 0.0 ? azimuth + 360.0 : azimuth);
                return "toward " + human3(s.direction) + buf;
            });
        // Another form of the direction: read together once both are known, never written.
        b.custom("elevation", nullptr, nullptr)
            .doc("number", "degrees above the horizon, -90 .. 90; needs `azimuth`")
            .shown("-")
            .ranged(elevationBounds);
        b.custom("azimuth", nullptr, nullptr)
            .doc("number", "degrees, 0 = +Z, 90 = +X; needs `elevation`")
            .shown("-")
            .thenCheck([](JsonReader& r, const QJsonObject& o, const KeyPath& path, SunDesc& sun) {
                if (!o.contains(QLatin1String("elevation"))) return;
                const double elevation = r.number(o.value(QLatin1String("elevation")), path.field("elevation"));
                const double azimuth = r.number(o.value(QLatin1String("azimuth")), path.field("azimuth"));
                if (!elevationBounds.holds(elevation))
                    r.fail(path.field("elevation"), elevationBounds.problem() + ", got " + json::fmt(elevation));
                sun.direction = sunDirection(elevation, azimuth);
            });
        // A third form: the date, clock time and place (NOAA's solar position), stored instead of the direction.
        auto placeField = [&b](const char* key, auto read, auto write) -> json::Field<SunDesc>& {
            return b.custom(
                         key,
                         [read](JsonReader& r, const QJsonValue& v, const KeyPath& p, SunDesc& s) {
                             if (!s.place) s.place = sky::SunPlace{};
                             read(r, v, p, *s.place);
                         },
                         [write](JsonWriter& w, const SunDesc& s, const KeyPath& p, int) { write(w, *s.place, p); })
                .writtenIf([](const SunDesc& s) { return s.place.has_value(); })
                .shown("-");
        };
        placeField(
            "date",
            [](JsonReader& r, const QJsonValue& v, const KeyPath& p, sky::SunPlace& pl) {
                if (!sky::parseSunDate(r.string(v, p).toStdString(), &pl.year, &pl.month, &pl.day))
                    r.fail(p, "expected a date \"YYYY-MM-DD\", got " + json::quoted(v.toString()));
            },
            [](JsonWriter& w, const sky::SunPlace& pl, const KeyPath&) { w.string(sky::formatSunDate(pl)); })
            .doc("string", "`\"YYYY-MM-DD\"`: the sun by date, time and place (NOAA's solar position, about 0.02 degrees); needs `time`, "
                           "`timezone`, `latitude`, `longitude`; instead of `direction`")
            .summarized([](const SunDesc& s) {
                if (!s.place) return std::string();
                char buf[200];
                std::snprintf(buf, sizeof buf, "on %s at %s UTC%+g, latitude %.4f, longitude %.4f", sky::formatSunDate(*s.place).c_str(),
                              sky::formatSunTime(s.place->hour).c_str(), s.place->timeZoneHours, s.place->latitudeDeg, s.place->longitudeDeg);
                return std::string(buf);
            });
        placeField(
            "time",
            [](JsonReader& r, const QJsonValue& v, const KeyPath& p, sky::SunPlace& pl) {
                if (!sky::parseSunTime(r.string(v, p).toStdString(), &pl.hour))
                    r.fail(p, "expected a local clock time \"HH:MM\" or \"HH:MM:SS\", got " + json::quoted(v.toString()));
            },
            [](JsonWriter& w, const sky::SunPlace& pl, const KeyPath&) { w.string(sky::formatSunTime(pl.hour)); })
            .doc("string", "`\"HH:MM[:SS]\"`: local clock time, 00:00 .. 24:00; with `date`");
        const auto placeNumber = [&placeField](const char* key, double sky::SunPlace::*member, double limit, const char* rule) {
            placeField(
                key,
                [member, limit](JsonReader& r, const QJsonValue& v, const KeyPath& p, sky::SunPlace& pl) {
                    const double x = r.number(v, p);
                    if (!(std::abs(x) <= limit)) r.fail(p, "must lie in [" + json::fmt(-limit) + ", " + json::fmt(limit) + "], got " + json::fmt(x));
                    pl.*member = x;
                },
                [member](JsonWriter& w, const sky::SunPlace& pl, const KeyPath& p) { w.number(pl.*member, p); })
                .doc("number", rule)
                .ranged(Bounds{.lo = -limit, .hi = limit});
        };
        placeNumber("timezone", &sky::SunPlace::timeZoneHours, 14.0, "hours of local time ahead of UTC (east +: 1 for CET, 2 for CEST), -14 .. 14; with `date`");
        placeNumber("latitude", &sky::SunPlace::latitudeDeg, 90.0, "degrees north (south negative), -90 .. 90; with `date`");
        placeNumber("longitude", &sky::SunPlace::longitudeDeg, 180.0, "degrees east (west negative), -180 .. 180; with `date`");
        b.table.fields.back().then = [](JsonReader& r, const QJsonObject&, const KeyPath& path, SunDesc& sun) {
            if (!sun.place) return;
            try {
                sun.direction = sky::placeSunDirection(*sun.place);
            } catch (const Error& e) {
                r.fail(path, e.what());
            }
        };
        b.number("temperature", &SunDesc::temperature, Bounds{.lo = 1000.0, .hi = 40000.0, .unit = " kelvin"})
            .doc("number", "blackbody colour temperature, 1000 .. 40000 K")
            .summarized([](const SunDesc& s) {
                char buf[64];
                std::snprintf(buf, sizeof buf, "%.0f K", s.temperature);
                return std::string(buf);
            });
        b.number("intensity", &SunDesc::intensity, atLeast(0.0))
            .doc("number", "scales the sun's radiance, >= 0")
            .summarized([](const SunDesc& s) { return "intensity " + human(s.intensity); });
        b.table.before = [](JsonReader& r, const QJsonObject& o, const KeyPath& path, SunDesc&) {
            const bool hasDirection = o.contains(QLatin1String("direction"));
            const bool hasElevation = o.contains(QLatin1String("elevation")), hasAzimuth = o.contains(QLatin1String("azimuth"));
            if (hasDirection && (hasElevation || hasAzimuth))
                r.fail(path, "give either \"direction\" or \"elevation\" and \"azimuth\", not both");
            static const char* const kPlace[] = {"date", "time", "timezone", "latitude", "longitude"};
            int placeKeys = 0;
            for (const char* k : kPlace) placeKeys += o.contains(QLatin1String(k)) ? 1 : 0;
            if (placeKeys > 0 && (hasDirection || hasElevation || hasAzimuth))
                r.fail(path, "give one of \"direction\", \"elevation\" and \"azimuth\", or \"date\", \"time\", \"timezone\", \"latitude\" and \"longitude\"");
            if (placeKeys > 0)
                for (const char* k : kPlace)
                    if (!o.contains(QLatin1String(k)))
                        r.fail(path.field(k), "missing (the sun by date and place needs date, time, timezone, latitude and longitude)");
            if (hasElevation && !hasAzimuth) r.fail(path.field("azimuth"), "missing (required with \"elevation\")");
            if (hasAzimuth && !hasElevation) r.fail(path.field("elevation"), "missing (required with \"azimuth\")");
        };
        return b.table;
    }();
    return table;
}

const char* skyKindName(sky::SkyKind k)
{
    switch (k) {
    case sky::SkyKind::Preetham: return "preetham";
    case sky::SkyKind::Map: return "hdri";
    case sky::SkyKind::Uniform: return "uniform";
    default: return "constant";
    }
}

bool parseSkyKind(const std::string& name, sky::SkyKind* out)
{
    for (sky::SkyKind k : {sky::SkyKind::Constant, sky::SkyKind::Preetham, sky::SkyKind::Map, sky::SkyKind::Uniform})
        if (name == skyKindName(k)) {
            *out = k;
            return true;
        }
    return false;
}

const Table<Scene>& skyTable()
{
    static const Table<Scene> table = [] {
        TableBuilder<Scene> b(Layout::Inline);
        b.enumeration("kind", [](auto& s) -> auto& { return s.skyModel.kind; }, parseSkyKind, skyKindName, "sky kind", "constant, preetham, hdri, uniform")
            .doc("string",
                 "`constant` (`color` everywhere: the background and the ground's ambient light; leaves and bark get none), "
                 "`preetham` (Preetham et al. 1999, the sun's direction), `hdri` (an equirectangular map, `path`), `uniform` (`color` "
                 "everywhere as a map: its virtual lights light leaves, bark and ground with shadow rays, the closer one to a path "
                 "tracer: [ACCURACY.md](ACCURACY.md) \"Ground truth\")")
            .writtenIf([](const Scene& s) { return s.skyModel.analytic(); })
            .summarized([](const Scene& s) { return std::string(skyKindName(s.skyModel.kind)) + " sky"; });
        b.color("color", &Scene::sky, 0.0f, kNoUpperBound)
            .doc("`[r, g, b]`", "`constant`, `uniform`: the sky's radiance, each >= 0")
            .writtenIf([](const Scene& s) { return s.skyModel.hasColor(); })
            .summarized([](const Scene& s) { return s.skyModel.hasColor() ? "radiance " + human3(s.sky) : std::string(); });
        b.number("turbidity", [](auto& s) -> auto& { return s.skyModel.turbidity; }, Bounds{.lo = sky::kMinTurbidity, .hi = sky::kMaxTurbidity})
            .doc("number", "`preetham` or with `aerial_perspective`: atmospheric turbidity, 2 (clear) .. 10 (hazy): the sky's and sun's colour, "
                           "and the haze of the distance")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Preetham || s.skyModel.aerialPerspective; })
            .summarized([](const Scene& s) {
                return s.skyModel.kind == sky::SkyKind::Preetham ? "turbidity " + human(s.skyModel.turbidity) : std::string();
            });
        b.number("scale", [](auto& s) -> auto& { return s.skyModel.scale; }, above(0.0))
            .doc("number", "`preetham`: multiplies the model's kcd/m^2 (sky and sun), > 0; 0.03 puts a high sun near `sun.intensity` 1's")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Preetham; });
        b.custom(
             "path",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, Scene& sc) { sc.skyModel.path = readFilePath(in(r), v, p, "an environment map"); },
             [](JsonWriter& w, const Scene& sc, const KeyPath&, int) { w.string(storedMeshPath(sc.skyModel.path, out(w).base)); })
            .doc("string", "`hdri`: equirectangular map (`.exr`, `.hdr`; 2:1, row 0 at the zenith); relative paths start at the scene file's folder")
            .shown("-")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Map; })
            .summarized([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Map ? s.skyModel.path : std::string(); });
        b.number("rotation_deg", [](auto& s) -> auto& { return s.skyModel.rotationDeg; })
            .doc("number", "`hdri`: degrees about +Y, added to every azimuth of the map (its sun turns with it)")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Map; });
        b.number("intensity", [](auto& s) -> auto& { return s.skyModel.intensity; }, atLeast(0.0))
            .doc("number", "`hdri`: multiplies the map's pixels (and its sun), >= 0")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Map; });
        b.boolean("sun_from_map", [](auto& s) -> auto& { return s.skyModel.sunFromMap; })
            .doc("bool",
                 "`hdri`: the map's sun (its brightest compact region) is taken out of the map and replaces `sun` (direction and "
                 "radiance, x `sun.intensity`); false: the map lights as it is and `sun` stays")
            .writtenIf([](const Scene& s) { return s.skyModel.kind == sky::SkyKind::Map; });
        b.boolean("aerial_perspective", [](auto& s) -> auto& { return s.skyModel.aerialPerspective; })
            .doc("bool",
                 "any sky: the air between the camera and what it sees, Rayleigh and aerosol (`turbidity`) thinning with height: distant "
                 "surfaces fade toward the sky at the horizon ([RENDERING.md](RENDERING.md) \"Aerial perspective\"); false (the default: files "
                 "without the key keep their picture) or true; the quality presets turn it on for scenes with a terrain")
            .writtenIf([](const Scene& s) { return s.skyModel.aerialPerspective; })
            .summarized([](const Scene& s) { return s.skyModel.aerialPerspective ? std::string("aerial perspective") : std::string(); });
        b.integer("lights", [](auto& s) -> auto& { return s.skyModel.lights; }, sky::kMinVirtualLights, sky::kMaxVirtualLights)
            .doc("integer",
                 "`preetham`, `hdri`, `uniform`: virtual directional lights the sky is split into (equal power; with the ground plane the upper hemisphere only), 1 .. 65536; the default 32 with `interleave` 16 (2 shadow rays a sample) on the default forest under a Preetham sky and two maps: at most 1.96% light error at 16 spp and 8% at 1 spp, at 1.8x-2.0x the sun-only frame's time ([ACCURACY.md](ACCURACY.md) \"Sky light\"; 64 lights: 1.35% at 2.5x-3.0x)")
            .writtenIf([](const Scene& s) { return s.skyModel.analytic(); })
            .summarized([](const Scene& s) {
                return s.skyModel.analytic() ? std::to_string(s.skyModel.lights) + " lights / " + std::to_string(s.skyModel.interleave) + " subsets"
                                             : std::string();
            });
        b.integer("interleave", [](auto& s) -> auto& { return s.skyModel.interleave; }, 1, sky::kMaxVirtualLights)
            .doc("integer",
                 "`preetham`, `hdri`, `uniform`: K subsets of the lights, one per pixel of each K-pixel block and cycled over the samples "
                 "(lights / K shadow rays a pixel and sample; spp >= K uses every light in every pixel), 1 .. `lights`; default 16 (see `lights`)")
            .writtenIf([](const Scene& s) { return s.skyModel.analytic(); });
        b.table.after = [](JsonReader& r, const QJsonObject& o, const KeyPath& path, Scene& sc) {
            const SkyDesc& d = sc.skyModel;
            auto only = [&](const char* key, bool allowed, const char* kinds) {
                if (o.contains(QLatin1String(key)) && !allowed)
                    r.fail(path.field(key), std::string("only with kind ") + kinds + " (the sky is " + skyKindName(d.kind) + ")");
            };
            only("color", d.hasColor(), "constant or uniform");
            if (o.contains(QLatin1String("turbidity")) && d.kind != sky::SkyKind::Preetham && !d.aerialPerspective)
                r.fail(path.field("turbidity"), std::string("only with kind preetham or aerial_perspective true (the sky is ") + skyKindName(d.kind) + ")");
            only("scale", d.kind == sky::SkyKind::Preetham, "preetham");
            only("path", d.kind == sky::SkyKind::Map, "hdri");
            only("rotation_deg", d.kind == sky::SkyKind::Map, "hdri");
            only("intensity", d.kind == sky::SkyKind::Map, "hdri");
            only("sun_from_map", d.kind == sky::SkyKind::Map, "hdri");
            only("lights", d.analytic(), "preetham, hdri or uniform");
            only("interleave", d.analytic(), "preetham, hdri or uniform");
            if (d.kind == sky::SkyKind::Map && d.path.empty()) r.fail(path.field("path"), "missing (required with kind hdri: the map)");
            if (d.interleave > d.lights)
                r.fail(path.field("interleave"), "must be at most lights (" + std::to_string(d.lights) + "), got " + std::to_string(d.interleave));
            if (!std::isfinite(d.rotationDeg)) r.fail(path.field("rotation_deg"), "must be finite");
        };
        return b.table;
    }();
    return table;
}

// The scene's `lighting` block: how the LB grids and the drawn sun share the direct light.
const Table<LightingDesc>& sceneLightingTable()
{
    static const Table<LightingDesc> table = [] {
        TableBuilder<LightingDesc> b(Layout::Inline);
        b.enumeration("direct", &LightingDesc::direct, parseDirectLight, directLightName, "direct light", "seed, once")
            .doc("string",
                 "`seed`: the grid as solved is added to the shadow-rayed sun (the seed's sum: direct light counted twice inside "
                 "crowns; the default of scene files, so old ones keep their picture); `once`: the grid less its uncollided sunlight, "
                 "weighed as light from all directions (leaves min(kd x (1 + t), 0.98) / 4 per channel, bark kd / 4), so it adds only "
                 "scattered light (closer to Cycles on the stand, the forest and under a Preetham or map sky; with `sky.kind` uniform "
                 "the closest on every scene measured, and what a new scene in the studio starts with: [ACCURACY.md](ACCURACY.md))")
            .summarized([](const LightingDesc& l) { return std::string("direct light ") + directLightName(l.direct); });
        b.enumeration("boundary", &LightingDesc::boundary, parseLbBoundary, lbBoundaryName, "LB boundary", "sun, sun_sky")
            .doc("string",
                 "`sun` (default: the seed's boundary, the sun alone; old files keep their picture) or `sun_sky`: each lattice direction's boundary value also gets the sky's radiance over its share of the upper hemisphere (any `sky.kind`; constant: `sky.color`), so leaves receive skylight scattered through the crown too, in the renderer's units of the sun (a sky without a sun still lights the grid) ([RENDERING.md](RENDERING.md) \"The sky in the LB boundary\")")
            .summarized([](const LightingDesc& l) { return std::string("LB boundary ") + lbBoundaryName(l.boundary); });
        b.enumeration("forest_grid", &LightingDesc::forestGrid, parseForestGridMode, forestGridModeName, "forest grid", "off, auto, on")
            .doc("string",
                 "the forest-level LB grid (Geist & Steele, section 3): `off` (default: every instance of a species lit alike), `on` "
                 "(each instance's species lighting scaled by the grid's factors: stand interiors darker, the open side of an "
                 "edge tree lit), `auto` (as `on` where the factors spread by 2% or more, else skipped; `render --stats` says which). "
                 "With a landscape, its tile plants too: one lattice over the terrain whose ground is opaque, valley and shaded-slope "
                 "plants darker than ridge plants ([RENDERING.md](RENDERING.md))")
            .summarized([](const LightingDesc& l) { return std::string("forest grid ") + forestGridModeName(l.forestGrid); });
        b.integer("forest_grid_resolution", &LightingDesc::forestGridResolution, 0, 512)
            .doc("integer", "forest grid nodes along the plants' longest horizontal extent, 4 .. 512, or 0 (the default): "
                                "automatic, 4 nodes across the median crown and at most 32 (the picture improves over no forest "
                                "grid from about 4 cells a crown: [ACCURACY.md](ACCURACY.md) \"Scene scale\"); build + solve "
                                "time in [PERFORMANCE.md](PERFORMANCE.md). A landscape's lattice: 0 gives 64 nodes along the terrain's longer "
                                "side, other values are clamped to 128")
            .thenCheck([](JsonReader& r, const QJsonObject&, const KeyPath& path, LightingDesc& l) {
                if (l.forestGridResolution > 0 && l.forestGridResolution < 4)
                    r.fail(path.field("forest_grid_resolution"), "expected 0 (automatic) or 4 .. 512, got " + std::to_string(l.forestGridResolution));
            })
            .summarized([](const LightingDesc& l) {
                if (l.forestGrid == ForestGridMode::Off) return std::string();
                return l.forestGridResolution == 0 ? std::string("forest grid resolution automatic")
                                                   : "forest grid resolution " + std::to_string(l.forestGridResolution);
            });
        b.integer("bounces", &LightingDesc::bounces, 0, kMaxPathBounces)
            .doc("integer", "the LB model as a radiance cache: bounces a camera path traces, 0 .. " + std::to_string(kMaxPathBounces) +
                                ", next-event estimation to the sun and sky at each of its surfaces, before the LB grid's scattered light "
                                "ends it. 0 (the default; old files keep their picture): the grid at the camera's hit, as the seed; 1: a "
                                "final gather; more: closer to the path tracer, slower. With 1 or more the paths carry all direct light "
                                "(the sky on leaves, the sun through them), so the grids give their scattered light only, as with "
                                "`direct` once ([RENDERING.md](RENDERING.md) \"The LB grid as a radiance cache\")")
            .summarized([](const LightingDesc& l) {
                return l.bounces > 0 ? "radiance cache after " + std::to_string(l.bounces) + (l.bounces == 1 ? " bounce" : " bounces")
                                     : std::string();
            });
        return b.table;
    }();
    return table;
}

const Table<CameraDesc>& cameraTable()
{
    static const Table<CameraDesc> table = [] {
        TableBuilder<CameraDesc> b(Layout::Inline);
        b.vector("position", &CameraDesc::position).doc("`[x, y, z]`", "metres").summarized([](const CameraDesc& c) {
            return "at " + human3(c.position);
        });
        b.vector("target", &CameraDesc::target)
            .doc("`[x, y, z]`", "metres; must differ from `position`")
            .summarized([](const CameraDesc& c) { return " looking at " + human3(c.target); }, true);
        b.vector("up", &CameraDesc::up)
            .doc("`[x, y, z]`", "non-zero, not parallel to `target - position`")
            .summarized([](const CameraDesc& c) { return "up " + human3(c.up); });
        b.number("fov", &CameraDesc::fovY, Bounds{.lo = 0.0, .hi = 180.0, .loOpen = true, .hiOpen = true, .unit = " degrees"})
            .doc("number", "vertical field of view, degrees, in (0, 180)")
            .summarized([](const CameraDesc& c) { return "vertical fov " + human(c.fovY) + " deg"; });
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& path, CameraDesc& cam) {
            const glm::dvec3 view = cam.target - cam.position;
            const double viewLength = glm::length(view);
            if (!(viewLength > 0.0) || !std::isfinite(viewLength))
                r.fail(path.field("target"), "must differ from camera.position " + json::fmt3(cam.position));
            if (!(glm::length(cam.up) >= 1e-12f)) r.fail(path.field("up"), "must be a non-zero vector (length >= 1e-12)");
            const glm::dvec3 up(cam.up);
            const double upLength = glm::length(up);
            if (glm::length(glm::cross(view / viewLength, up / upLength)) < 1e-6)
                r.fail(path.field("up"), json::fmt3(up) + " is parallel to the view direction (target - position) " + json::fmt3(view));
        };
        return b.table;
    }();
    return table;
}

const Table<RenderSettings>& renderTable()
{
    static const Table<RenderSettings> table = [] {
        TableBuilder<RenderSettings> b(Layout::Inline);
        b.integer("width", &RenderSettings::width, 1, 32768).doc("integer", "pixels, 1 .. 32768").summarized([](const RenderSettings& r) {
            return std::to_string(r.width);
        });
        b.integer("height", &RenderSettings::height, 1, 32768)
            .doc("integer", "pixels, 1 .. 32768")
            .summarized([](const RenderSettings& r) { return "x" + std::to_string(r.height); }, true);
        b.integer("spp", &RenderSettings::spp, 1, 4096).doc("integer", "samples per pixel, 1 .. 4096").summarized([](const RenderSettings& r) {
            return std::to_string(r.spp) + " spp";
        });
        b.enumeration("mode", &RenderSettings::mode, parseRenderMode, renderModeName, "mode", "full, local, ambient, lb")
            .doc("string", "`full`, `local`, `ambient`, `lb`")
            .summarized([](const RenderSettings& r) { return std::string("mode ") + renderModeName(r.mode); });
        b.enumeration("accel", &RenderSettings::accel, parseAccel, accelName, "acceleration structure", "bvh, kdtree")
            .doc("string", "`bvh`, `kdtree`")
            .summarized([](const RenderSettings& r) { return std::string(accelName(r.accel)); });
        b.boolean("shadows", &RenderSettings::shadows).doc("bool", "sun shadows").summarized([](const RenderSettings& r) {
            return std::string("shadows ") + (r.shadows ? "on" : "off");
        });
        b.number("indirect", &RenderSettings::indirectScale, atLeast(0.0))
            .doc("number", "weight of the LB indirect light, >= 0")
            .summarized([](const RenderSettings& r) { return "indirect " + human(r.indirectScale); });
        b.number("key", &RenderSettings::exposureKey, above(0.0))
            .doc("number", "Reinhard key value, > 0: the picture is exposed so its log-average luminance is this grey, for every `view`").summarized([](const RenderSettings& r) {
            return "key " + human(r.exposureKey);
        });
        b.color("leaf_tint", &RenderSettings::leafTint, 0.0f, 2.0f)
            .doc("`[r, g, b]`", "multiplies every leaf material's diffuse colour (what leaves reflect and, with `path`, transmit), "
                                "each in [0, 2]; 1 = as modelled")
            .writtenIf([](const RenderSettings& r) { return r.leafTint != glm::vec3(1.0f); })
            .summarized([](const RenderSettings& r) { return r.leafTint != glm::vec3(1.0f) ? "leaf tint " + human3(r.leafTint) : std::string(); });
        // Names, not checked here: the views a config offers depend on $OCIO; a render checks them before its work.
        b.custom(
             "view",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, RenderSettings& t) {
                 t.view = r.string(v, p).toStdString();
                 if (t.view.empty()) r.fail(p, "must name a view (\"" + std::string(kReinhardView) + "\": the seed's picture)");
             },
             [](JsonWriter& w, const RenderSettings& t, const KeyPath&, int) { w.string(t.view); })
            .doc("string",
                 "the picture's display transform: `\"Sylva Reinhard\"` (the seed's Reinhard curve with the key) or a view of the "
                 "OpenColorIO config (bundled: `Standard`, `ACES 1.0 SDR-video`, `Sylva Filmic`; `$OCIO`'s when set), exposed with the "
                 "key; `.exr` stays linear; `sylva render --list-views` ([RENDERING.md](RENDERING.md) \"Display transforms\")")
            .writtenIf([](const RenderSettings& t) { return t.view != kReinhardView; })
            .summarized([](const RenderSettings& r) { return r.view != kReinhardView ? "view " + r.view : std::string(); });
        b.custom(
             "display",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, RenderSettings& t) { t.display = r.string(v, p).toStdString(); },
             [](JsonWriter& w, const RenderSettings& t, const KeyPath&, int) { w.string(t.display); })
            .doc("string", "the OpenColorIO display of `view` (empty: the config's default display, `sRGB` in the bundled one)")
            .writtenIf([](const RenderSettings& t) { return !t.display.empty(); })
            .summarized([](const RenderSettings& r) { return r.display.empty() ? std::string() : "display " + r.display; });
        b.number("alpha_distance", &RenderSettings::alphaDistance, atLeast(0.0, " (metres; 0 = off)"))
            .doc("number",
                 "metres, >= 0; beyond it from the camera leaf cut-outs are not tested (cards opaque); 0 = off "
                 "([RENDERING.md](RENDERING.md))")
            .summarized([](const RenderSettings& r) {
                return r.alphaDistance > 0.0f ? "alpha tests within " + human(r.alphaDistance) + " m" : std::string();
            });
        b.number("prune_distance", &RenderSettings::pruneDistance, atLeast(0.0, " (metres; 0 = off)"))
            .doc("number", "metres, >= 0; stochastic pruning of leaves starts there (half the leaves at twice it, area-preserving); 0 = off")
            .summarized([](const RenderSettings& r) {
                return r.pruneDistance > 0.0f ? "leaves pruned from " + human(r.pruneDistance) + " m" : std::string();
            });
        b.enumeration("integrator", &RenderSettings::integrator, parseIntegrator, integratorName, "integrator", "lb, path")
            .doc("string", "`lb`: the LB model (direct light with shadow rays and the LB grids' scattered light); `path`: the reference "
                           "path tracer (every bounce, next-event estimation to the sun and sky, Russian roulette; no volumes yet; "
                           "[RENDERING.md](RENDERING.md) \"The path tracer\")")
            .summarized([](const RenderSettings& r) {
                return r.integrator == Integrator::Path ? "path tracer, at most " + std::to_string(r.maxBounces) + " bounces" : std::string();
            });
        b.integer("max_bounces", &RenderSettings::maxBounces, 0, kMaxPathBounces)
            .doc("integer", "`path`: bounces after the camera's hit, 0 .. " + std::to_string(kMaxPathBounces) +
                                " (0: direct light only; Russian roulette from the 4th)");
        b.integer("bounce_samples", &RenderSettings::bounceSamples, 0, 4096)
            .doc("integer", "`lb` with `lighting.bounces` > 0: how many of a pixel's `spp` samples trace the bounces (every "
                            "spp / N-th); the others take their surface's direct light and the traced samples' bounced light in "
                            "proportion to their albedo ([RENDERING.md](RENDERING.md) \"Bounce samples\"); 0 = every sample")
            .writtenIf([](const RenderSettings& r) { return r.bounceSamples != 0; })
            .summarized([](const RenderSettings& r) {
                return r.bounceSamples > 0 ? std::to_string(r.bounceSamples) + " bounce samples" : std::string();
            });
        return b.table;
    }();
    return table;
}

// "KEY: summary of the object's fields\n" for `sylva info`.
template <class U, class Get>
std::function<std::string(const Scene&)> sectionLine(const char* key, Get get, const Table<U>& table)
{
    return [key, get, &table](const Scene& s) { return std::string(key) + ": " + json::summarize(get(s), table) + "\n"; };
}

} // namespace

const Table<Scene>& sceneTable()
{
    static const Table<Scene> table = [] {
        TableBuilder<Scene> b(Layout::Block);
        b.custom(
             "version",
             [](JsonReader& r, const QJsonValue& v, const KeyPath& p, Scene& s) {
                 const double n = r.number(v, p);
                 if (n != double(kSceneFileVersion))
                     r.fail(p, "unsupported version " + json::fmt(n) + " (this build reads version " + std::to_string(kSceneFileVersion) + ")");
                 s.version = kSceneFileVersion;
             },
             [](JsonWriter& w, const Scene&, const KeyPath&, int) { w.integer((long long)kSceneFileVersion); })
            .doc("integer", "must be 1")
            .required("missing (required; this build reads version 1)")
            .shown("required")
            .summarized([](const Scene& s) {
                return "scene version " + std::to_string(s.version) + ": " + std::to_string(s.species.size()) + " species, " +
                       std::to_string(s.instances.size()) + " instances\n";
            });
        // A scene of ground, terrain, sky and volumes alone (look development before any plant) has neither.
        b.array("species", &Scene::species, speciesTable(), nullptr, size_t(std::numeric_limits<uint32_t>::max()), "too many species")
            .required(nullptr)
            .doc("object", "the plants' kinds; none for a scene of ground, terrain, sky and volumes alone")
            .shown("[]")
            .summarized(describeSpecies);
        b.array("instances", &Scene::instances, instanceTable(), nullptr)
            .required(nullptr)
            .doc("object", "the plants placed; each names a species or a group")
            .shown("[]")
            .summarized(describeInstances);
        b.object("ground", &Scene::ground, groundTable())
            .doc("object", "")
            .summarized(sectionLine("ground", [](const Scene& s) -> const GroundDesc& { return s.ground; }, groundTable()));
        {
            json::Field<Scene>& f = b.custom(
                "terrain",
                [](JsonReader& r, const QJsonValue& v, const KeyPath& p, Scene& sc) {
                    readObject(r, r.object(v, p), p, sc.terrain, terrainTable());
                },
                [](JsonWriter& w, const Scene& sc, const KeyPath& p, int indent) { writeObject(w, sc.terrain, p, terrainTable(), indent); });
            f.writeIf = [](const Scene& sc) { return sc.terrain.enabled(); };
            f.nested = true;
            f.children = [](std::vector<json::FieldRow>& o, const std::string& path) { documentFields(terrainTable(), path, o); };
            f.doc("object", "a terrain from a DEM (replaces the ground plane); optional")
                .shown("")
                .summarized([line = sectionLine("terrain", [](const Scene& sc) -> const TerrainDesc& { return sc.terrain; }, terrainTable())](
                                const Scene& sc) { return sc.terrain.enabled() ? line(sc) : std::string(); });
        }
        b.array("volumes", &Scene::volumes, volumeTable(), nullptr, 4096, "too many volumes (at most 4096)")
            .required(nullptr)
            .writtenIf([](const Scene& sc) { return !sc.volumes.empty(); })
            .doc("object", "participating media (clouds, smoke): a density grid, optics, tracer, placements; optional")
            .shown("[]")
            .summarized(describeVolumes);
        b.object("sun", &Scene::sun, sunTable())
            .doc("object", "`direction`, or `elevation` with `azimuth`, or `date`, `time`, `timezone`, `latitude` and `longitude`; one of the three")
            .summarized(sectionLine("sun", [](const Scene& s) -> const SunDesc& { return s.sun; }, sunTable()));
        b.object("sky", [](auto& s) -> auto& { return s; }, skyTable())
            .doc("object", "")
            .summarized(sectionLine("sky", [](const Scene& s) -> const Scene& { return s; }, skyTable()));
        b.object("lighting", &Scene::lighting, sceneLightingTable())
            .writtenIf([](const Scene& sc) { return !(sc.lighting == LightingDesc{}); })
            .doc("object", "the scene's lighting beyond sun and sky; optional")
            .summarized(sectionLine("lighting", [](const Scene& s) -> const LightingDesc& { return s.lighting; }, sceneLightingTable()));
        b.object("camera", &Scene::camera, cameraTable())
            .doc("object", "pinhole")
            .summarized(sectionLine("camera", [](const Scene& s) -> const CameraDesc& { return s.camera; }, cameraTable()));
        b.object("render", &Scene::render, renderTable())
            .doc("object", "")
            .summarized(sectionLine("render", [](const Scene& s) -> const RenderSettings& { return s.render; }, renderTable()));
        b.table.after = [](JsonReader& r, const QJsonObject&, const KeyPath& path, Scene& sc) {
            for (size_t i = 0; i < sc.instances.size() && !sc.terrain.enabled(); ++i)
                if (sc.instances[i].onTerrain)
                    r.fail(path.field("instances").at(qsizetype(i)).field("on_terrain"), "needs a terrain (the scene has no \"terrain\")");
        };
        return b.table;
    }();
    return table;
}

namespace {

std::vector<json::FieldRow> sceneFieldRows()
{
    std::vector<json::FieldRow> rows;
    json::documentFields(sceneTable(), "", rows);
    return rows;
}

} // namespace

std::vector<json::FieldDoc> sceneFieldDocs()
{
    const std::vector<json::FieldRow> rows = sceneFieldRows();
    return std::vector<json::FieldDoc>(rows.begin(), rows.end());
}

json::Bounds sceneFieldRange(const std::string& key)
{
    static const std::vector<json::FieldRow> rows = sceneFieldRows();
    for (const json::FieldRow& d : rows) {
        if (d.key != key) continue;
        if (!d.range) throw Error("scene field " + key + " has no bounds");
        return *d.range;
    }
    throw Error("no scene field " + key);
}

} // namespace sylva
