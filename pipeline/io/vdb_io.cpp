// OpenVDB files of density, wood fraction and lighting grids (vdb_io.h). The only file that includes
// OpenVDB's headers.
#include "pipeline/io/vdb_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/number_text.h"
#include "core/base/version.h"
#include "pipeline/io/atomic_file.h"

namespace fs = std::filesystem;

namespace sylva {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

// Relative tolerance of the transform checks: a voxel size or an axis may differ by this much from
// the exact uniform, axis-aligned map (rounding in another program's matrix products), no more.
constexpr double kTransformTolerance = 1e-6;

void initializeVdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

std::string quoted(const std::string& name)
{
    return "'" + name + "'";
}

std::string triple(double a, double b, double c)
{
    return "(" + numberText(a, kFloatDigits) + ", " + numberText(b, kFloatDigits) + ", " + numberText(c, kFloatDigits) + ")";
}

// ---- writing ----

openvdb::math::Transform::Ptr makeTransform(const GridGeometry& g)
{
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(g.spacing);
    xf->postTranslate(openvdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    return xf;
}

CoordBBox nodeBox(const GridGeometry& g)
{
    return CoordBBox(Coord(0, 0, 0), Coord(g.dims.x - 1, g.dims.y - 1, g.dims.z - 1));
}

// The metadata every grid of a file carries (vdb_io.h).
struct FileMetadata {
    std::optional<QJsonObject> parameters;
    std::string parametersText;
};

void addMetadata(openvdb::GridBase& grid, const GridGeometry& g, const char* kind, const FileMetadata& meta)
{
    grid.setCreator(std::string("Sylva ") + versionString());
    grid.insertMeta("sylva_dims", openvdb::Vec3IMetadata(openvdb::Vec3i(g.dims.x, g.dims.y, g.dims.z)));
    grid.insertMeta("sylva_kind", openvdb::StringMetadata(kind));
    grid.insertMeta("sylva_version", openvdb::StringMetadata(versionString()));
    if (!meta.parameters) return;
    for (auto it = meta.parameters->begin(); it != meta.parameters->end(); ++it) {
        const std::string key = "sylva_" + it.key().toStdString();
        const QJsonValue v = it.value();
        if (v.isDouble()) {
            grid.insertMeta(key, openvdb::DoubleMetadata(v.toDouble()));
        } else if (v.isBool()) {
            grid.insertMeta(key, openvdb::BoolMetadata(v.toBool()));
        } else if (v.isString()) {
            grid.insertMeta(key, openvdb::StringMetadata(v.toString().toStdString()));
        } else if (v.isArray() && v.toArray().size() == 3 && v.toArray()[0].isDouble() && v.toArray()[1].isDouble() &&
                   v.toArray()[2].isDouble()) {
            const QJsonArray a = v.toArray();
            grid.insertMeta(key, openvdb::Vec3DMetadata(openvdb::Vec3d(a[0].toDouble(), a[1].toDouble(), a[2].toDouble())));
        } else {
            const QJsonDocument doc = v.isArray() ? QJsonDocument(v.toArray()) : QJsonDocument(v.toObject());
            grid.insertMeta(key, openvdb::StringMetadata(v.isNull() ? std::string("null") : doc.toJson(QJsonDocument::Compact).toStdString()));
        }
    }
    grid.insertMeta("sylva_parameters", openvdb::StringMetadata(meta.parametersText));
}

// A sparse grid of the values (z fastest, as every Sylva grid): zeros are inactive background, equal
// values over a whole leaf become a tile (copyFromDense's pruning, exact with tolerance 0).
template <class GridT>
typename GridT::Ptr sparseGrid(typename GridT::ValueType* values, const GridGeometry& g, const std::string& name)
{
    using ValueT = typename GridT::ValueType;
    typename GridT::Ptr grid = GridT::create(openvdb::zeroVal<ValueT>());
    const openvdb::tools::Dense<ValueT, openvdb::tools::LayoutZYX> dense(nodeBox(g), values);
    openvdb::tools::copyFromDense(dense, *grid, openvdb::zeroVal<ValueT>(), false);
    grid->setName(name);
    grid->setTransform(makeTransform(g));
    return grid;
}

void checkValueCount(const std::string& path, const char* what, size_t have, size_t want)
{
    if (have != want)
        throw Error(path + ": the " + what + " grid holds " + std::to_string(have) + " values but its dims need " + std::to_string(want));
}

void checkGeometry(const std::string& path, const GridGeometry& g)
{
    if (g.dims.x <= 0 || g.dims.y <= 0 || g.dims.z <= 0) throw Error(path + ": refusing to write a grid with empty dims");
    if (!(g.spacing > 0.0) || !std::isfinite(g.spacing)) throw Error(path + ": the grid spacing must be a positive number");
    if (!std::isfinite(g.origin.x) || !std::isfinite(g.origin.y) || !std::isfinite(g.origin.z))
        throw Error(path + ": the grid origin must be finite");
}

// ---- reading ----

std::string gridList(const openvdb::GridPtrVec& grids)
{
    std::string out;
    for (const openvdb::GridBase::Ptr& g : grids) out += (out.empty() ? "" : ", ") + quoted(g->getName()) + " (" + g->valueType() + ")";
    return out.empty() ? std::string("no grids") : out;
}

class VdbReader {
public:
    explicit VdbReader(const std::string& path) : m_path(path)
    {
        std::error_code ec;
        if (!fs::exists(path, ec)) throw Error(path + ": no such file");
        if (fs::is_directory(path, ec)) throw Error(path + ": is a folder, not an OpenVDB file");
        if (fs::file_size(path, ec) == 0) throw Error(path + ": empty file, not an OpenVDB file");
        initializeVdb();
        m_file = std::make_unique<openvdb::io::File>(path);
        try {
            m_file->open(false);
            m_grids = m_file->readAllGridMetadata();
        } catch (const std::exception& e) {
            throw Error(path + ": not a readable OpenVDB file (" + e.what() + ")");
        }
    }
    ~VdbReader()
    {
        if (m_file->isOpen()) m_file->close();
    }
    VdbReader(const VdbReader&) = delete;
    VdbReader& operator=(const VdbReader&) = delete;

    const std::string& path() const { return m_path; }
    const openvdb::GridPtrVec& grids() const { return *m_grids; }
    openvdb::io::File& file() { return *m_file; }

    const openvdb::GridBase* find(const std::string& name) const
    {
        for (const openvdb::GridBase::Ptr& g : *m_grids)
            if (g->getName() == name) return g.get();
        return nullptr;
    }

    // The grid NAME, which must be of type GridT (else an Error naming its type).
    template <class GridT>
    typename GridT::Ptr read(const std::string& name)
    {
        const openvdb::GridBase* meta = find(name);
        if (!meta) throw Error(m_path + ": no grid " + quoted(name) + " (the file holds " + gridList(*m_grids) + ")");
        if (!meta->isType<GridT>())
            throw Error(m_path + ": grid " + quoted(name) + " holds " + meta->valueType() + " values, not " +
                        openvdb::typeNameAsString<typename GridT::ValueType>());
        openvdb::GridBase::Ptr base;
        try {
            base = m_file->readGrid(name);
        } catch (const std::exception& e) {
            throw Error(m_path + ": cannot read grid " + quoted(name) + " (" + e.what() + ")");
        }
        typename GridT::Ptr grid = openvdb::gridPtrCast<GridT>(base);
        if (!grid) throw Error(m_path + ": cannot read grid " + quoted(name));
        if (grid->getGridClass() == openvdb::GRID_LEVEL_SET)
            throw Error(m_path + ": grid " + quoted(name) +
                        " is a level set (a signed distance, not a density); convert it to a fog volume first");
        return grid;
    }

private:
    std::string m_path;
    std::unique_ptr<openvdb::io::File> m_file;
    openvdb::GridPtrVecPtr m_grids;
};

// The spacing of a grid's transform; Error unless it is linear, axis-aligned, unmirrored and uniform.
double uniformSpacing(const std::string& path, const openvdb::GridBase& grid)
{
    const openvdb::math::Transform& xf = grid.constTransform();
    const std::string name = quoted(grid.getName());
    const char* needs = "; Sylva grids are axis-aligned with one voxel size (resample the grid first)";
    if (!xf.isLinear()) throw Error(path + ": grid " + name + " has a frustum (non-linear) transform" + needs);
    const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();   // row vectors: world = index * m
    double scale = 0.0;
    for (int a = 0; a < 3; ++a) scale = std::max(scale, std::fabs(m(a, a)));
    double offDiagonal = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (r != c) offDiagonal = std::max(offDiagonal, std::fabs(m(r, c)));
    if (!(scale > 0.0) || !std::isfinite(scale)) throw Error(path + ": grid " + name + " has a degenerate transform (voxel size 0)");
    if (offDiagonal > kTransformTolerance * scale)
        throw Error(path + ": grid " + name + " has a rotated or sheared transform" + needs);
    if (m(0, 0) < 0.0 || m(1, 1) < 0.0 || m(2, 2) < 0.0) throw Error(path + ": grid " + name + " has a mirrored transform" + needs);
    const double s = m(0, 0);
    if (std::fabs(m(1, 1) - s) > kTransformTolerance * s || std::fabs(m(2, 2) - s) > kTransformTolerance * s)
        throw Error(path + ": grid " + name + " has a non-uniform voxel size " + triple(m(0, 0), m(1, 1), m(2, 2)) + needs);
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(m(3, a))) throw Error(path + ": grid " + name + " has a non-finite translation");
    return s;
}

// Where a grid's nodes lie: the index box of node (0,0,0) .. (dims-1) and the geometry it gives.
struct Placement {
    CoordBBox box;
    GridGeometry geometry;
};

// `active`: the active voxels' bounding box of the grid (or of the grids read together).
Placement placement(const std::string& path, const openvdb::GridBase& grid, const CoordBBox& active)
{
    Placement p;
    p.geometry.spacing = uniformSpacing(path, grid);
    const std::string name = quoted(grid.getName());
    const openvdb::Vec3IMetadata::ConstPtr dims = grid.getMetadata<openvdb::Vec3IMetadata>("sylva_dims");
    if (dims) {
        const openvdb::Vec3i d = dims->value();
        if (d.x() < 1 || d.y() < 1 || d.z() < 1)
            throw Error(path + ": grid " + name + " has sylva_dims " + triple(d.x(), d.y(), d.z()) + "; each must be at least 1");
        p.box = CoordBBox(Coord(0, 0, 0), Coord(d.x() - 1, d.y() - 1, d.z() - 1));
        if (!active.empty() && !p.box.isInside(active))
            throw Error(path + ": grid " + name + " has active voxels outside its sylva_dims " + triple(d.x(), d.y(), d.z()));
    } else {
        if (active.empty()) throw Error(path + ": grid " + name + " has no active voxels");
        p.box = active;
        p.box.expand(1);   // a node of zeros around the medium: the LB boundary lies outside it
    }
    const openvdb::Coord extent = p.box.dim();
    const double nodes = double(extent.x()) * double(extent.y()) * double(extent.z());
    if (nodes > double(kVdbMaxNodes))
        throw Error(path + ": grid " + name + " spans " + std::to_string(extent.x()) + "x" + std::to_string(extent.y()) + "x" +
                    std::to_string(extent.z()) + " nodes; Sylva reads at most " + std::to_string(kVdbMaxNodes) +
                    " nodes (512^3) from a .vdb");
    p.geometry.dims = {extent.x(), extent.y(), extent.z()};
    const openvdb::Vec3d origin = grid.constTransform().indexToWorld(p.box.min());
    p.geometry.origin = {origin.x(), origin.y(), origin.z()};
    return p;
}

// Calls store(node index, value) for every active voxel and every voxel of an active tile inside
// p.box: the leaves in parallel (each node is stored once), the tiles after.
template <class TreeT, class Store>
void forEachActive(const TreeT& tree, const Placement& p, Store&& store)
{
    using LeafT = typename TreeT::LeafNodeType;
    const Coord lo = p.box.min();
    auto nodeIndex = [&](const Coord& c) { return p.geometry.index(c.x() - lo.x(), c.y() - lo.y(), c.z() - lo.z()); };
    std::vector<const LeafT*> leaves;
    leaves.reserve(tree.leafCount());
    tree.getNodes(leaves);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t l = r.begin(); l != r.end(); ++l)
            for (auto it = leaves[l]->cbeginValueOn(); it; ++it) {
                const Coord c = it.getCoord();
                if (p.box.isInside(c)) store(nodeIndex(c), *it);
            }
    });
    typename TreeT::ValueOnCIter tile = tree.cbeginValueOn();
    tile.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);   // tiles only: the leaves were done above
    for (; tile; ++tile) {
        CoordBBox b;
        tile.getBoundingBox(b);
        b.intersect(p.box);
        if (b.empty()) continue;
        for (int x = b.min().x(); x <= b.max().x(); ++x)
            for (int y = b.min().y(); y <= b.max().y(); ++y)
                for (int z = b.min().z(); z <= b.max().z(); ++z) store(nodeIndex(Coord(x, y, z)), *tile);
    }
}

void requireSameTransform(const std::string& path, const openvdb::GridBase& a, const openvdb::GridBase& b)
{
    if (!(a.constTransform() == b.constTransform()))
        throw Error(path + ": grids " + quoted(a.getName()) + " and " + quoted(b.getName()) + " have different transforms");
}

template <class GridT>
std::string valueRangeText(const GridT& grid)
{
    using ValueT = typename GridT::ValueType;
    auto it = grid.cbeginValueOn();
    if (!it) return "no active values";
    ValueT lo = *it, hi = *it;
    for (; it; ++it) {
        const ValueT v = *it;
        if constexpr (std::is_same_v<ValueT, float>) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        } else {
            for (int c = 0; c < 3; ++c) {
                lo[c] = std::min(lo[c], v[c]);
                hi[c] = std::max(hi[c], v[c]);
            }
        }
    }
    if constexpr (std::is_same_v<ValueT, float>) return "values " + numberText(lo, kFloatDigits) + " .. " + numberText(hi, kFloatDigits);
    else return "values " + triple(lo[0], lo[1], lo[2]) + " .. " + triple(hi[0], hi[1], hi[2]);
}

} // namespace

void writeVdbFile(const std::string& path, const DensityGrid* density, const LightingGrid* lighting, const std::string& parametersJson)
{
    if (!density && !lighting) throw Error(path + ": no grid to write");
    const GridGeometry& g = density ? density->geometry : lighting->geometry;
    checkGeometry(path, g);
    if (density && lighting && !(density->geometry == lighting->geometry))
        throw Error(path + ": the density and lighting grids of one file must share their dims, origin and spacing");
    const size_t n = g.nodeCount();
    if (density) {
        checkValueCount(path, "density", density->density.size(), n);
        if (!density->woodFraction.empty()) checkValueCount(path, "wood fraction", density->woodFraction.size(), n);
    }
    if (lighting) checkValueCount(path, "lighting", lighting->rgb.size(), n * 3);
    FileMetadata meta;
    if (!parametersJson.empty()) {
        QJsonParseError parseError;
        const QJsonDocument doc = QJsonDocument::fromJson(QByteArray::fromStdString(parametersJson), &parseError);
        if (!doc.isObject())
            throw Error(path + ": the grid parameters must be a JSON object" +
                        (doc.isNull() ? " (" + parseError.errorString().toStdString() + ")" : std::string()));
        meta.parameters = doc.object();
        meta.parametersText = QJsonDocument(*meta.parameters).toJson(QJsonDocument::Compact).toStdString();
    }
    AtomicFile out(path, AtomicFile::Sync::Yes, "OpenVDB file");
    initializeVdb();
    try {
        openvdb::GridPtrVec grids;
        if (density) {
            // The dense wrappers read the values only; Dense takes a non-const pointer.
            openvdb::FloatGrid::Ptr d = sparseGrid<openvdb::FloatGrid>(const_cast<float*>(density->density.data()), g, kVdbDensityGrid);
            d->setGridClass(openvdb::GRID_FOG_VOLUME);
            addMetadata(*d, g, "density", meta);
            grids.push_back(d);
            std::vector<float> zeros;
            if (density->woodFraction.empty()) zeros.assign(n, 0.0f);
            float* wood = const_cast<float*>(density->woodFraction.empty() ? zeros.data() : density->woodFraction.data());
            openvdb::FloatGrid::Ptr w = sparseGrid<openvdb::FloatGrid>(wood, g, kVdbWoodGrid);
            addMetadata(*w, g, "density", meta);
            grids.push_back(w);
        }
        if (lighting) {
            static_assert(sizeof(openvdb::Vec3s) == 3 * sizeof(float), "Vec3s must be three packed floats");
            auto* rgb = reinterpret_cast<openvdb::Vec3s*>(const_cast<float*>(lighting->rgb.data()));
            openvdb::Vec3SGrid::Ptr l = sparseGrid<openvdb::Vec3SGrid>(rgb, g, kVdbLightingGrid);
            l->setVectorType(openvdb::VEC_INVARIANT);
            addMetadata(*l, g, "lighting", meta);
            grids.push_back(l);
            std::vector<float> channel(n);
            for (int c = 0; c < 3; ++c) {
                tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
                    for (size_t i = r.begin(); i != r.end(); ++i) channel[i] = lighting->rgb[i * 3 + size_t(c)];
                });
                openvdb::FloatGrid::Ptr ch = sparseGrid<openvdb::FloatGrid>(channel.data(), g, kVdbLightingChannelGrids[c]);
                addMetadata(*ch, g, "lighting", meta);
                grids.push_back(ch);
            }
        }
        openvdb::MetaMap fileMeta;
        fileMeta.insertMeta("creator", openvdb::StringMetadata(std::string("Sylva ") + versionString()));
        openvdb::io::File file(out.pathForWriter());
        file.write(grids, fileMeta);
        file.close();
    } catch (const openvdb::Exception& e) {
        throw Error(path + ": cannot write the OpenVDB file (" + e.what() + ")");
    }
    out.commit();
}

DensityGrid readVdbDensity(const std::string& path)
{
    VdbReader vdb(path);
    std::string name;
    if (const openvdb::GridBase* named = vdb.find(kVdbDensityGrid)) {
        if (!named->isType<openvdb::FloatGrid>())
            throw Error(path + ": grid 'density' holds " + named->valueType() + " values; a density must be a float grid");
        name = kVdbDensityGrid;
    } else {
        for (const openvdb::GridBase::Ptr& g : vdb.grids())   // OpenVDB lists a file's grids by name
            if (g->isType<openvdb::FloatGrid>()) {
                name = g->getName();
                break;
            }
    }
    if (name.empty())
        throw Error(path + ": no float grid to read a density from (the file holds " + gridList(vdb.grids()) +
                    "); Sylva reads the float grid 'density', else the first float grid");
    const openvdb::FloatGrid::Ptr grid = vdb.read<openvdb::FloatGrid>(name);
    const Placement p = placement(path, *grid, grid->evalActiveVoxelBoundingBox());
    DensityGrid out;
    out.geometry = p.geometry;
    out.density.assign(p.geometry.nodeCount(), 0.0f);
    forEachActive(grid->tree(), p, [&](size_t i, float v) { out.density[i] = v; });
    out.woodFraction.assign(out.density.size(), 0.0f);
    if (name != kVdbWoodGrid && vdb.find(kVdbWoodGrid)) {
        const openvdb::FloatGrid::Ptr wood = vdb.read<openvdb::FloatGrid>(kVdbWoodGrid);
        requireSameTransform(path, *grid, *wood);
        forEachActive(wood->tree(), p, [&](size_t i, float v) { out.woodFraction[i] = v; });
    }
    return out;
}

LightingGrid readVdbLighting(const std::string& path)
{
    VdbReader vdb(path);
    LightingGrid out;
    if (vdb.find(kVdbLightingGrid)) {
        const openvdb::Vec3SGrid::Ptr grid = vdb.read<openvdb::Vec3SGrid>(kVdbLightingGrid);
        const Placement p = placement(path, *grid, grid->evalActiveVoxelBoundingBox());
        out.geometry = p.geometry;
        out.rgb.assign(p.geometry.nodeCount() * 3, 0.0f);
        forEachActive(grid->tree(), p, [&](size_t i, const openvdb::Vec3s& v) {
            for (int c = 0; c < 3; ++c) out.rgb[i * 3 + size_t(c)] = v[c];
        });
        return out;
    }
    for (const char* channel : kVdbLightingChannelGrids)
        if (!vdb.find(channel))
            throw Error(path + ": no lighting grid (a vec3s grid 'lighting' or the float grids 'lighting_r', 'lighting_g' and "
                               "'lighting_b'; the file holds " +
                        gridList(vdb.grids()) + ")");
    openvdb::FloatGrid::Ptr channels[3];
    CoordBBox active;
    for (int c = 0; c < 3; ++c) {
        channels[c] = vdb.read<openvdb::FloatGrid>(kVdbLightingChannelGrids[c]);
        if (c > 0) requireSameTransform(path, *channels[0], *channels[c]);
        active.expand(channels[c]->evalActiveVoxelBoundingBox());
    }
    const Placement p = placement(path, *channels[0], active);
    out.geometry = p.geometry;
    out.rgb.assign(p.geometry.nodeCount() * 3, 0.0f);
    for (int c = 0; c < 3; ++c)
        forEachActive(channels[c]->tree(), p, [&](size_t i, float v) { out.rgb[i * 3 + size_t(c)] = v; });
    return out;
}

std::string describeVdbFile(const std::string& path)
{
    VdbReader vdb(path);
    std::string text = path + ": OpenVDB file (format " + vdb.file().version() + "), " + std::to_string(vdb.grids().size()) +
                       (vdb.grids().size() == 1 ? " grid\n" : " grids\n");
    // Each grid's sylva_* metadata as text, then what every grid has alike (printed once).
    std::vector<std::map<std::string, std::string>> metadata;
    std::vector<std::string> lines;
    for (const openvdb::GridBase::Ptr& meta : vdb.grids()) {
        const std::string name = meta->getName();
        openvdb::GridBase::Ptr grid;
        try {
            grid = vdb.file().readGrid(name);
        } catch (const std::exception& e) {
            throw Error(path + ": cannot read grid " + quoted(name) + " (" + e.what() + ")");
        }
        const CoordBBox box = grid->evalActiveVoxelBoundingBox();
        const openvdb::Vec3d voxel = grid->voxelSize();
        const openvdb::Vec3d origin = grid->constTransform().indexToWorld(openvdb::Vec3d(0.0));
        std::string line = "grid " + quoted(name) + ": " + grid->valueType() + ", class " + openvdb::GridBase::gridClassToString(grid->getGridClass()) +
                ", " + std::to_string(grid->activeVoxelCount()) + " active voxels";
        if (!box.empty())
            line += ", index box " + triple(box.min().x(), box.min().y(), box.min().z()) + " .. " +
                    triple(box.max().x(), box.max().y(), box.max().z());
        line += ", voxel size " + triple(voxel.x(), voxel.y(), voxel.z()) + ", voxel (0,0,0) at " + triple(origin.x(), origin.y(), origin.z());
        if (const auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) line += ", " + valueRangeText(*f);
        else if (const auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid)) line += ", " + valueRangeText(*v);
        lines.push_back(line + "\n");
        std::map<std::string, std::string>& m = metadata.emplace_back();
        for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it)
            if (it->first.rfind("sylva_", 0) == 0 && it->first != "sylva_parameters") m[it->first] = it->second->str();
    }
    std::map<std::string, std::string> shared = metadata.empty() ? std::map<std::string, std::string>() : metadata.front();
    for (const auto& m : metadata)
        for (auto it = shared.begin(); it != shared.end();) {
            const auto found = m.find(it->first);
            it = found == m.end() || found->second != it->second ? shared.erase(it) : std::next(it);
        }
    if (metadata.size() < 2) shared.clear();
    for (size_t g = 0; g < lines.size(); ++g) {
        text += lines[g];
        for (const auto& [key, value] : metadata[g])
            if (!shared.count(key)) text += "  " + key + " = " + value + "\n";
    }
    if (!shared.empty()) {
        text += "every grid:\n";
        for (const auto& [key, value] : shared) text += "  " + key + " = " + value + "\n";
    }
    // What `sylva light --density` would make of it.
    try {
        const DensityGrid d = readVdbDensity(path);
        text += "as a Sylva density: " + std::to_string(d.geometry.dims.x) + "x" + std::to_string(d.geometry.dims.y) + "x" +
                std::to_string(d.geometry.dims.z) + " nodes, spacing " + numberText(d.geometry.spacing, kFloatDigits) + ", node (0,0,0) at " +
                triple(d.geometry.origin.x, d.geometry.origin.y, d.geometry.origin.z) + "\n";
    } catch (const Error& e) {
        std::string why = e.what();
        if (why.rfind(path + ": ", 0) == 0) why = why.substr(path.size() + 2);
        text += "as a Sylva density: not readable (" + why + ")\n";
    }
    return text;
}

} // namespace sylva
