// Study results to and from JSON (QJsonDocument), the Pareto front, run descriptions.
#include "pipeline/study/study_data.h"

#include <algorithm>
#include <ctime>
#include <fstream>
#include <numeric>
#include <thread>

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

namespace sylva::study {
namespace {

QString qs(const std::string& s) { return QString::fromStdString(s); }
std::string str(const QJsonObject& o, const char* key) { return o.value(QLatin1String(key)).toString().toStdString(); }
double num(const QJsonObject& o, const char* key) { return o.value(QLatin1String(key)).toDouble(); }
int integer(const QJsonObject& o, const char* key) { return o.value(QLatin1String(key)).toInt(); }
bool flag(const QJsonObject& o, const char* key) { return o.value(QLatin1String(key)).toBool(); }

QJsonObject runToJson(const RunInfo& r)
{
    QJsonObject o;
    o["date"] = qs(r.date);
    o["machine"] = qs(r.machine);
    o["quick"] = r.quick;
    o["seconds"] = r.seconds;
    o["load_before"] = r.loadBefore;
    o["load_after"] = r.loadAfter;
    return o;
}

RunInfo runFromJson(const QJsonObject& o)
{
    RunInfo r;
    r.date = str(o, "date");
    r.machine = str(o, "machine");
    r.quick = flag(o, "quick");
    r.seconds = num(o, "seconds");
    r.loadBefore = num(o, "load_before");
    r.loadAfter = num(o, "load_after");
    return r;
}

void save(const std::string& path, const QJsonObject& root)
{
    const QByteArray text = QJsonDocument(root).toJson(QJsonDocument::Indented);
    AtomicFile f(path);
    f.write(text.constData(), size_t(text.size()));
    f.commit();
}

bool load(const std::string& path, QJsonObject* root)
{
    QFile f(qs(path));
    if (!f.exists()) return false;
    if (!f.open(QIODevice::ReadOnly)) throw Error(path + ": cannot read: " + f.errorString().toStdString());
    QJsonParseError err;
    const QJsonDocument doc = QJsonDocument::fromJson(f.readAll(), &err);
    if (doc.isNull() || !doc.isObject()) throw Error(path + ": not a study result file: " + err.errorString().toStdString());
    *root = doc.object();
    return true;
}

template <typename T, typename F>
QJsonArray array(const std::vector<T>& v, F f)
{
    QJsonArray a;
    for (const T& x : v) a.append(f(x));
    return a;
}

template <typename T, typename F>
std::vector<T> list(const QJsonValue& v, F f)
{
    std::vector<T> out;
    for (const QJsonValue& x : v.toArray()) out.push_back(f(x.toObject()));
    return out;
}

} // namespace

void saveLb(const std::string& path, const LbData& d)
{
    QJsonObject root;
    root["run"] = runToJson(d.run);
    root["note"] = qs(d.note);
    root["default_config"] = qs(d.defaultConfig);
    root["cases"] = array(d.cases, [](const LbCase& c) {
        QJsonObject o;
        o["name"] = qs(c.name);
        o["title"] = qs(c.title);
        o["preset"] = qs(c.preset);
        o["fine_grid"] = c.fineGrid;
        o["skipped"] = qs(c.skipped);
        o["references"] = array(c.references, [](const LbReference& r) {
            QJsonObject x;
            x["grid"] = r.grid;
            x["dims"] = qs(r.dims);
            x["paths"] = r.paths;
            x["noise"] = r.noise;
            x["seconds"] = r.seconds;
            x["cached"] = r.cached;
            return x;
        });
        o["rows"] = array(c.rows, [](const LbRow& r) {
            QJsonObject x;
            x["grid"] = r.grid;
            x["dims"] = qs(r.dims);
            x["steps"] = qs(r.steps);
            x["fp16"] = r.fp16;
            x["seconds"] = r.seconds;
            x["cpu_seconds"] = r.cpuSeconds;
            x["steps_taken"] = r.stepsTaken;
            x["err_same"] = r.errSame;
            x["err_fine"] = r.errFine;
            x["default"] = r.isDefault;
            return x;
        });
        return o;
    });
    save(path, root);
}

bool loadLb(const std::string& path, LbData* d)
{
    QJsonObject root;
    if (!load(path, &root)) return false;
    d->run = runFromJson(root.value("run").toObject());
    d->note = str(root, "note");
    d->defaultConfig = str(root, "default_config");
    d->cases = list<LbCase>(root.value("cases"), [](const QJsonObject& o) {
        LbCase c;
        c.name = str(o, "name");
        c.title = str(o, "title");
        c.preset = str(o, "preset");
        c.fineGrid = integer(o, "fine_grid");
        c.skipped = str(o, "skipped");
        c.references = list<LbReference>(o.value("references"), [](const QJsonObject& x) {
            LbReference r;
            r.grid = integer(x, "grid");
            r.dims = str(x, "dims");
            r.paths = num(x, "paths");
            r.noise = num(x, "noise");
            r.seconds = num(x, "seconds");
            r.cached = flag(x, "cached");
            return r;
        });
        c.rows = list<LbRow>(o.value("rows"), [](const QJsonObject& x) {
            LbRow r;
            r.grid = integer(x, "grid");
            r.dims = str(x, "dims");
            r.steps = str(x, "steps");
            r.fp16 = flag(x, "fp16");
            r.seconds = num(x, "seconds");
            r.cpuSeconds = num(x, "cpu_seconds");
            r.stepsTaken = integer(x, "steps_taken");
            r.errSame = num(x, "err_same");
            r.errFine = num(x, "err_fine");
            r.isDefault = flag(x, "default");
            return r;
        });
        return c;
    });
    return true;
}

void saveVoxel(const std::string& path, const VoxelData& d)
{
    QJsonObject root;
    root["run"] = runToJson(d.run);
    root["reference_subcells"] = d.referenceSubcells;
    root["rows"] = array(d.rows, [](const VoxelRow& r) {
        QJsonObject x;
        x["case"] = qs(r.caseName);
        x["grid"] = r.grid;
        x["subcells"] = r.subcells;
        x["voxel_seconds"] = r.voxelSeconds;
        x["mean_vs_3"] = r.meanVs3;
        x["density_err"] = r.densityErr;
        x["lb_err"] = r.lbErr;
        return x;
    });
    save(path, root);
}

bool loadVoxel(const std::string& path, VoxelData* d)
{
    QJsonObject root;
    if (!load(path, &root)) return false;
    d->run = runFromJson(root.value("run").toObject());
    d->referenceSubcells = integer(root, "reference_subcells");
    d->rows = list<VoxelRow>(root.value("rows"), [](const QJsonObject& x) {
        VoxelRow r;
        r.caseName = str(x, "case");
        r.grid = integer(x, "grid");
        r.subcells = integer(x, "subcells");
        r.voxelSeconds = num(x, "voxel_seconds");
        r.meanVs3 = num(x, "mean_vs_3");
        r.densityErr = num(x, "density_err");
        r.lbErr = num(x, "lb_err");
        return r;
    });
    return true;
}

void saveRender(const std::string& path, const RenderData& d)
{
    QJsonObject root;
    root["run"] = runToJson(d.run);
    root["spp_scene"] = qs(d.sppScene);
    root["spp_width"] = d.sppWidth;
    root["spp_height"] = d.sppHeight;
    root["spp_reference"] = d.sppReference;
    root["spp"] = array(d.spp, [](const SppRow& r) {
        QJsonObject x;
        x["spp"] = r.spp;
        x["trace_seconds"] = r.traceSeconds;
        x["trace_cpu"] = r.traceCpu;
        x["err"] = r.err;
        return x;
    });
    root["lod_scene"] = qs(d.lodScene);
    root["lod_width"] = d.lodWidth;
    root["lod_height"] = d.lodHeight;
    root["lod_spps"] = array(d.lodSpps, [](int v) { return QJsonValue(v); });
    root["lod_reference_spp"] = d.lodReferenceSpp;
    root["lod_reference_seconds"] = d.lodReferenceSeconds;
    root["lod"] = array(d.lod, [](const LodRow& r) {
        QJsonObject x;
        x["label"] = qs(r.label);
        x["alpha_distance"] = double(r.alphaDistance);
        x["prune_distance"] = double(r.pruneDistance);
        x["build_seconds"] = r.buildSeconds;
        x["trace_seconds"] = array(r.traceSeconds, [](double v) { return QJsonValue(v); });
        x["trace_cpu"] = array(r.traceCpu, [](double v) { return QJsonValue(v); });
        x["err"] = array(r.err, [](double v) { return QJsonValue(v); });
        x["err_off"] = array(r.errOff, [](double v) { return QJsonValue(v); });
        x["instanced_triangles"] = r.instancedTriangles;
        x["prune_megabytes"] = r.pruneMegabytes;
        x["default"] = r.isDefault;
        return x;
    });
    root["preset_reference_spp"] = d.presetReferenceSpp;
    root["preset_reference_seconds"] = d.presetReferenceSeconds;
    root["presets"] = array(d.presets, [](const PresetRow& r) {
        QJsonObject x;
        x["name"] = qs(r.name);
        x["build_seconds"] = r.buildSeconds;
        x["trace_seconds"] = r.traceSeconds;
        x["trace_cpu"] = r.traceCpu;
        x["err"] = r.err;
        return x;
    });
    save(path, root);
}

bool loadRender(const std::string& path, RenderData* d)
{
    QJsonObject root;
    if (!load(path, &root)) return false;
    d->run = runFromJson(root.value("run").toObject());
    d->sppScene = str(root, "spp_scene");
    d->sppWidth = integer(root, "spp_width");
    d->sppHeight = integer(root, "spp_height");
    d->sppReference = integer(root, "spp_reference");
    d->spp = list<SppRow>(root.value("spp"), [](const QJsonObject& x) {
        SppRow r;
        r.spp = integer(x, "spp");
        r.traceSeconds = num(x, "trace_seconds");
        r.traceCpu = num(x, "trace_cpu");
        r.err = num(x, "err");
        return r;
    });
    d->lodScene = str(root, "lod_scene");
    d->lodWidth = integer(root, "lod_width");
    d->lodHeight = integer(root, "lod_height");
    d->lodSpps.clear();
    for (const QJsonValue& v : root.value("lod_spps").toArray()) d->lodSpps.push_back(v.toInt());
    d->lodReferenceSpp = integer(root, "lod_reference_spp");
    d->lodReferenceSeconds = num(root, "lod_reference_seconds");
    d->lod = list<LodRow>(root.value("lod"), [](const QJsonObject& x) {
        LodRow r;
        r.label = str(x, "label");
        r.alphaDistance = float(num(x, "alpha_distance"));
        r.pruneDistance = float(num(x, "prune_distance"));
        r.buildSeconds = num(x, "build_seconds");
        for (const QJsonValue& v : x.value("trace_seconds").toArray()) r.traceSeconds.push_back(v.toDouble());
        for (const QJsonValue& v : x.value("trace_cpu").toArray()) r.traceCpu.push_back(v.toDouble());
        for (const QJsonValue& v : x.value("err").toArray()) r.err.push_back(v.toDouble());
        for (const QJsonValue& v : x.value("err_off").toArray()) r.errOff.push_back(v.toDouble());
        r.instancedTriangles = num(x, "instanced_triangles");
        r.pruneMegabytes = num(x, "prune_megabytes");
        r.isDefault = flag(x, "default");
        return r;
    });
    d->presetReferenceSpp = integer(root, "preset_reference_spp");
    d->presetReferenceSeconds = num(root, "preset_reference_seconds");
    d->presets = list<PresetRow>(root.value("presets"), [](const QJsonObject& x) {
        PresetRow r;
        r.name = str(x, "name");
        r.buildSeconds = num(x, "build_seconds");
        r.traceSeconds = num(x, "trace_seconds");
        r.traceCpu = num(x, "trace_cpu");
        r.err = num(x, "err");
        return r;
    });
    return true;
}

void saveScene(const std::string& path, const SceneData& d)
{
    QJsonObject root;
    root["run"] = runToJson(d.run);
    root["stand_scene"] = qs(d.standScene);
    root["width"] = d.width;
    root["height"] = d.height;
    root["spp"] = d.spp;
    root["species_grid"] = d.speciesGrid;
    root["crown_width"] = d.crownWidth;
    root["species_dims"] = qs(d.speciesDims);
    root["reference_dims"] = qs(d.referenceDims);
    root["reference_seconds"] = d.referenceSeconds;
    root["floor_err"] = d.floorErr;
    root["isolated_factor"] = d.isolatedFactor;
    root["oracle_err"] = d.oracleErr;
    root["reference_interior"] = d.referenceInterior;
    root["reference_edge"] = d.referenceEdge;
    root["forest"] = array(d.forest, [](const ForestGridRow& r) {
        QJsonObject x;
        x["resolution"] = r.resolution;
        x["automatic"] = r.automatic;
        x["dims"] = qs(r.dims);
        x["cells_per_crown"] = r.cellsPerCrown;
        x["seconds"] = r.seconds;
        x["image_err"] = r.imageErr;
        x["factor_rms"] = r.factorRms;
        x["factor_max"] = r.factorMax;
        x["interior"] = r.interior;
        x["edge"] = r.edge;
        x["default"] = r.isDefault;
        return x;
    });
    root["suns"] = d.suns;
    root["basis"] = array(d.basis, [](const BasisRow& r) {
        QJsonObject x;
        x["fp16"] = r.fp16;
        x["directions"] = r.directions;
        x["basis_seconds"] = r.basisSeconds;
        x["basis_cpu"] = r.basisCpu;
        x["direct_seconds"] = r.directSeconds;
        x["direct_cpu"] = r.directCpu;
        x["relight_ms"] = r.relightMs;
        x["megabytes"] = r.megabytes;
        x["err_median"] = r.errMedian;
        x["err_max"] = r.errMax;
        x["default"] = r.isDefault;
        return x;
    });
    save(path, root);
}

bool loadScene(const std::string& path, SceneData* d)
{
    QJsonObject root;
    if (!load(path, &root)) return false;
    d->run = runFromJson(root.value("run").toObject());
    d->standScene = str(root, "stand_scene");
    d->width = integer(root, "width");
    d->height = integer(root, "height");
    d->spp = integer(root, "spp");
    d->speciesGrid = integer(root, "species_grid");
    d->crownWidth = num(root, "crown_width");
    d->speciesDims = str(root, "species_dims");
    d->referenceDims = str(root, "reference_dims");
    d->referenceSeconds = num(root, "reference_seconds");
    d->floorErr = num(root, "floor_err");
    d->isolatedFactor = num(root, "isolated_factor");
    d->oracleErr = num(root, "oracle_err");
    d->referenceInterior = num(root, "reference_interior");
    d->referenceEdge = num(root, "reference_edge");
    d->forest = list<ForestGridRow>(root.value("forest"), [](const QJsonObject& x) {
        ForestGridRow r;
        r.resolution = integer(x, "resolution");
        r.automatic = flag(x, "automatic");
        r.dims = str(x, "dims");
        r.cellsPerCrown = num(x, "cells_per_crown");
        r.seconds = num(x, "seconds");
        r.imageErr = num(x, "image_err");
        r.factorRms = num(x, "factor_rms");
        r.factorMax = num(x, "factor_max");
        r.interior = num(x, "interior");
        r.edge = num(x, "edge");
        r.isDefault = flag(x, "default");
        return r;
    });
    d->suns = integer(root, "suns");
    d->basis = list<BasisRow>(root.value("basis"), [](const QJsonObject& x) {
        BasisRow r;
        r.fp16 = flag(x, "fp16");
        r.directions = integer(x, "directions");
        r.basisSeconds = num(x, "basis_seconds");
        r.basisCpu = num(x, "basis_cpu");
        r.directSeconds = num(x, "direct_seconds");
        r.directCpu = num(x, "direct_cpu");
        r.relightMs = num(x, "relight_ms");
        r.megabytes = num(x, "megabytes");
        r.errMedian = num(x, "err_median");
        r.errMax = num(x, "err_max");
        r.isDefault = flag(x, "default");
        return r;
    });
    return true;
}

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
