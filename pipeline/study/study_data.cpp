// Study results to and from JSON (Qt's QJsonDocument, each record's keys listed once), the Pareto front,
// run descriptions.
#include "pipeline/study/study_data.h"

#include <algorithm>
#include <ctime>
#include <fstream>
#include <numeric>
#include <thread>
#include <type_traits>

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

namespace sylva::study {
namespace {

// Each record's fields, listed once as (JSON key, member): the writer and the reader below walk the same
// list, so a key cannot be written under one name and read under another. `io` is a Writer or a Reader;
// R is the record, const when written.
template <class Io, class R>
void fields(Io& io, R& r)
{
    using T = std::remove_const_t<R>;
    if constexpr (std::is_same_v<T, RunInfo>) {
        io("date", r.date); io("machine", r.machine); io("quick", r.quick); io("seconds", r.seconds);
        io("load_before", r.loadBefore); io("load_after", r.loadAfter);
    } else if constexpr (std::is_same_v<T, LbReference>) {
        io("grid", r.grid); io("dims", r.dims); io("paths", r.paths); io("noise", r.noise); io("seconds", r.seconds);
        io("cached", r.cached);
    } else if constexpr (std::is_same_v<T, LbRow>) {
        io("grid", r.grid); io("dims", r.dims); io("steps", r.steps); io("fp16", r.fp16); io("seconds", r.seconds);
        io("cpu_seconds", r.cpuSeconds); io("steps_taken", r.stepsTaken); io("err_same", r.errSame); io("err_fine", r.errFine);
        io("default", r.isDefault);
    } else if constexpr (std::is_same_v<T, LbCase>) {
        io("name", r.name); io("title", r.title); io("preset", r.preset); io("fine_grid", r.fineGrid); io("skipped", r.skipped);
        io("references", r.references); io("rows", r.rows);
    } else if constexpr (std::is_same_v<T, LbData>) {
        io("run", r.run); io("note", r.note); io("default_config", r.defaultConfig); io("cases", r.cases);
    } else if constexpr (std::is_same_v<T, VoxelRow>) {
        io("case", r.caseName); io("grid", r.grid); io("subcells", r.subcells); io("voxel_seconds", r.voxelSeconds);
        io("mean_vs_3", r.meanVs3); io("density_err", r.densityErr); io("lb_err", r.lbErr);
    } else if constexpr (std::is_same_v<T, VoxelData>) {
        io("run", r.run); io("reference_subcells", r.referenceSubcells); io("rows", r.rows);
    } else if constexpr (std::is_same_v<T, SppRow>) {
        io("spp", r.spp); io("trace_seconds", r.traceSeconds); io("trace_cpu", r.traceCpu); io("err", r.err);
    } else if constexpr (std::is_same_v<T, LodRow>) {
        io("label", r.label); io("alpha_distance", r.alphaDistance); io("prune_distance", r.pruneDistance);
        io("build_seconds", r.buildSeconds); io("trace_seconds", r.traceSeconds); io("trace_cpu", r.traceCpu); io("err", r.err);
        io("err_off", r.errOff); io("instanced_triangles", r.instancedTriangles); io("prune_megabytes", r.pruneMegabytes);
        io("default", r.isDefault);
    } else if constexpr (std::is_same_v<T, PresetRow>) {
        io("name", r.name); io("build_seconds", r.buildSeconds); io("trace_seconds", r.traceSeconds); io("trace_cpu", r.traceCpu);
        io("err", r.err); io("settings", r.settings);
    } else if constexpr (std::is_same_v<T, RenderData>) {
        io("run", r.run); io("spp_scene", r.sppScene); io("spp_width", r.sppWidth); io("spp_height", r.sppHeight);
        io("spp_reference", r.sppReference); io("spp", r.spp); io("lod_scene", r.lodScene); io("lod_width", r.lodWidth);
        io("lod_height", r.lodHeight); io("lod_spps", r.lodSpps); io("lod_reference_spp", r.lodReferenceSpp);
        io("lod_reference_seconds", r.lodReferenceSeconds); io("lod", r.lod); io("preset_reference_spp", r.presetReferenceSpp);
        io("preset_reference_seconds", r.presetReferenceSeconds); io("presets", r.presets);
    } else if constexpr (std::is_same_v<T, ForestGridRow>) {
        io("resolution", r.resolution); io("automatic", r.automatic); io("dims", r.dims); io("cells_per_crown", r.cellsPerCrown);
        io("seconds", r.seconds); io("image_err", r.imageErr); io("factor_rms", r.factorRms); io("factor_max", r.factorMax);
        io("interior", r.interior); io("edge", r.edge); io("default", r.isDefault);
    } else if constexpr (std::is_same_v<T, BasisRow>) {
        io("fp16", r.fp16); io("directions", r.directions); io("basis_seconds", r.basisSeconds); io("basis_cpu", r.basisCpu);
        io("direct_seconds", r.directSeconds); io("direct_cpu", r.directCpu); io("relight_ms", r.relightMs);
        io("megabytes", r.megabytes); io("err_median", r.errMedian); io("err_max", r.errMax); io("default", r.isDefault);
    } else if constexpr (std::is_same_v<T, SceneData>) {
        io("run", r.run); io("stand_scene", r.standScene); io("width", r.width); io("height", r.height); io("spp", r.spp);
        io("species_grid", r.speciesGrid); io("crown_width", r.crownWidth); io("species_dims", r.speciesDims);
        io("reference_dims", r.referenceDims); io("reference_seconds", r.referenceSeconds); io("floor_err", r.floorErr);
        io("isolated_factor", r.isolatedFactor); io("oracle_err", r.oracleErr); io("reference_interior", r.referenceInterior);
        io("reference_edge", r.referenceEdge); io("forest", r.forest); io("suns", r.suns); io("basis", r.basis);
    } else {
        static_assert(sizeof(T) == 0, "a study record without a field list");
    }
}

// Turns a record into a QJsonObject: strings, numbers (float as double), booleans, arrays, nested records.
struct Writer {
    QJsonObject o;
    static QJsonValue value(const std::string& v) { return QString::fromStdString(v); }
    static QJsonValue value(bool v) { return v; }
    static QJsonValue value(int v) { return v; }
    static QJsonValue value(double v) { return v; }
    static QJsonValue value(float v) { return double(v); }
    template <class T>
    static QJsonValue value(const std::vector<T>& v)
    {
        QJsonArray a;
        for (const T& x : v) a.append(value(x));
        return a;
    }
    template <class R>
    static QJsonValue value(const R& record)
    {
        Writer w;
        fields(w, record);
        return w.o;
    }
    template <class T>
    void operator()(const char* key, const T& v) { o.insert(QLatin1String(key), value(v)); }
};

// Reads a record's members from a QJsonObject; an absent key reads as 0, false, "" or empty.
struct Reader {
    QJsonObject o;
    static void get(const QJsonValue& v, std::string& out) { out = v.toString().toStdString(); }
    static void get(const QJsonValue& v, bool& out) { out = v.toBool(); }
    static void get(const QJsonValue& v, int& out) { out = v.toInt(); }
    static void get(const QJsonValue& v, double& out) { out = v.toDouble(); }
    static void get(const QJsonValue& v, float& out) { out = float(v.toDouble()); }
    template <class T>
    static void get(const QJsonValue& v, std::vector<T>& out)
    {
        out.clear();
        for (const QJsonValue& x : v.toArray()) get(x, out.emplace_back());
    }
    template <class R>
    static void get(const QJsonValue& v, R& record)
    {
        Reader r{v.toObject()};
        fields(r, record);
    }
    template <class T>
    void operator()(const char* key, T& v) { get(o.value(QLatin1String(key)), v); }
};

template <class R>
void save(const std::string& path, const R& record)
{
    const QByteArray text = QJsonDocument(Writer::value(record).toObject()).toJson(QJsonDocument::Indented);
    AtomicFile f(path);
    f.write(text.constData(), size_t(text.size()));
    f.commit();
}

template <class R>
bool load(const std::string& path, R* record)
{
    QFile f(QString::fromStdString(path));
    if (!f.exists()) return false;
    if (!f.open(QIODevice::ReadOnly)) throw Error(path + ": cannot read: " + f.errorString().toStdString());
    QJsonParseError err;
    const QJsonDocument doc = QJsonDocument::fromJson(f.readAll(), &err);
    if (doc.isNull() || !doc.isObject()) throw Error(path + ": not a study result file: " + err.errorString().toStdString());
    Reader::get(doc.object(), *record);
    return true;
}

} // namespace

void saveLb(const std::string& path, const LbData& d) { save(path, d); }
bool loadLb(const std::string& path, LbData* d) { return load(path, d); }
void saveVoxel(const std::string& path, const VoxelData& d) { save(path, d); }
bool loadVoxel(const std::string& path, VoxelData* d) { return load(path, d); }
void saveRender(const std::string& path, const RenderData& d) { save(path, d); }
bool loadRender(const std::string& path, RenderData* d) { return load(path, d); }
void saveScene(const std::string& path, const SceneData& d) { save(path, d); }
bool loadScene(const std::string& path, SceneData* d) { return load(path, d); }

std::vector<size_t> paretoFront(const std::vector<double>& time, const std::vector<double>& error)
{
    std::vector<size_t> idx(time.size());
    std::iota(idx.begin(), idx.end(), size_t(0));
    std::sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return time[a] != time[b] ? time[a] < time[b] : error[a] < error[b]; });
    std::vector<size_t> front;
    double best = 1e300;
    for (size_t i : idx) {
        if (error[i] < best) {
            front.push_back(i);
            best = error[i];
        }
    }
    return front;
}

std::string today()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d", &tm);
    return buf;
}

double loadAverage()
{
    std::ifstream in("/proc/loadavg");
    double l = -1.0;
    if (!(in >> l)) return -1.0;
    return l;
}

std::string machineDescription()
{
    std::string model = "unknown CPU";
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) model = line.substr(colon + 2);
            break;
        }
    }
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " logical cores";
}

} // namespace sylva::study
