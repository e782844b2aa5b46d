// ExportController: render and grid exports through the pipeline's export services, in jobs.
#include "studio/export_controller.h"

#include <algorithm>

#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QMessageBox>

#include "core/backend/backend.h"
#include "core/base/error.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/services/exports.h"
#include "pipeline/services/gltf_export.h"
#include "studio/asset_store.h"
#include "studio/job_manager.h"
#include "studio/recent_files.h"
#include "studio/scene_document.h"

namespace sylva {

ExportController::ExportController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache,
                                   Backend* backend, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_jobs(jobs), m_assets(assets), m_cache(cache), m_backend(backend), m_window(window)
{
}

namespace {

// The species' assets of an export's scene (the lighting grids when its mode needs them), from the store or made.
std::vector<SpeciesAssets> exportAssets(const Scene& scene, AssetStore* store, GridCache* cache, Backend* backend, Job& job,
                                        Progress& progress)
{
    const bool lit = modeNeedsLighting(scene.render.mode);
    const std::vector<AssetsPtr> shared =
        ensureAssets(scene, lit, *store, cache, &progress, [&job](const std::string& line) { job.log(QString::fromStdString(line)); },
                     backend);
    std::vector<SpeciesAssets> assets;
    for (const AssetsPtr& a : shared) assets.push_back(*a);
    return assets;
}

} // namespace

std::vector<int> ExportController::renderSamplePasses(int spp, int subsets)
{
    const int total = std::max(1, spp), step = std::max(1, subsets);
    std::vector<int> ends;
    int done = std::min(total, step);
    ends.push_back(done);
    while (done < total) {
        const int more = std::max(step, done / step * step);   // double, in whole cycles of the subsets
        done = std::min(total, done + more);
        ends.push_back(done);
    }
    return ends;
}

Job* ExportController::renderImage(const Scene& scene, PassCallback onPass)
{
    if (scene.render.width < 1 || scene.render.height < 1 || scene.render.spp < 1) {
        fail(tr("Render failed"), tr("The render size and samples must be at least 1."));
        return nullptr;
    }
    GridCache* cache = m_cache;
    AssetStore* store = m_assets;
    Backend* backend = m_backend;
    log(tr("rendering %1 x %2, %3 spp").arg(scene.render.width).arg(scene.render.height).arg(scene.render.spp));
    return m_jobs->start(tr("Render image"),
                         [scene, store, cache, backend, onPass](Job& job, Progress& progress) {
                             SubProgress assetsPart(&progress, 0.0, 0.3);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<SpeciesAssets> assets = exportAssets(scene, store, cache, backend, job, assetsProgress);
                             progress.report(0.3, "building");
                             const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
                             if (progress.isCancelled()) throw Cancelled();
                             if (backend && backend->name() != "cpu") {
                                 SubProgress tracePart(&progress, 0.35, 1.0);
                                 Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
                                 onPass(backend->render(rs, &traceProgress), scene.render.spp);
                                 return;
                             }
                             const RenderView base = rs.view();
                             const std::vector<int> ends = renderSamplePasses(base.spp, base.sky.lightCount > 0 ? base.sky.interleave.subsets : 1);
                             Film sum;
                             int done = 0;
                             for (const int end : ends) {
                                 RenderView view = base;
                                 view.sampleBegin = done;
                                 view.sampleEnd = end;
                                 SubProgress passPart(&progress, 0.35 + 0.65 * done / base.spp, 0.35 + 0.65 * end / base.spp);
                                 Progress passProgress([&](double f, const std::string&) {
                                     passPart.report(f, "samples " + std::to_string(done) + " of " + std::to_string(base.spp));
                                 });
                                 if (progress.isCancelled()) throw Cancelled();
                                 const Film part = renderFilm(view, &passProgress);
                                 accumulateFilm(sum, done, part, end - done);
                                 done = end;
                                 onPass(sum, done);
                             }
                         },
                         [this](Job* job) {
                             if (job->state() == Job::State::Succeeded) log(tr("rendered in %1 s").arg(job->seconds(), 0, 'f', 2));
                             else if (job->state() == Job::State::Failed) fail(tr("Render failed"), job->error());
                             else log(tr("render cancelled"));
                         });
}

Job* ExportController::exportRender(const ExportSettings& settings)
{
    Scene scene = m_doc->scene();
    scene.render.width = settings.width;
    scene.render.height = settings.height;
    scene.render.spp = settings.spp;
    m_lastExport = settings;
    const std::string path = settings.path.toStdString();
    GridCache* cache = m_cache;
    AssetStore* store = m_assets;
    Backend* backend = m_backend;
    const bool passes = settings.passes;
    log(tr("exporting %1 (%2 x %3, %4 spp%5)")
            .arg(settings.path)
            .arg(settings.width)
            .arg(settings.height)
            .arg(settings.spp)
            .arg(passes ? tr(", render passes") : QString()));
    return m_jobs->start(tr("Export %1").arg(QFileInfo(settings.path).fileName()),
                         [scene, path, store, cache, backend, passes](Job& job, Progress& progress) {
                             SubProgress assetsPart(&progress, 0.0, 0.4);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<SpeciesAssets> assets = exportAssets(scene, store, cache, backend, job, assetsProgress);
                             SubProgress renderPart(&progress, 0.4, 1.0);
                             Progress renderProgress([&](double f, const std::string& m) { renderPart.report(f, m); });
                             sylva::exportRender(scene, assets, path, backend, &renderProgress, passes);
                         },
                         [this, settings, backend](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 log(tr("exported %1 in %2 s (backend: %3)")
                                         .arg(settings.path)
                                         .arg(job->seconds(), 0, 'f', 2)
                                         .arg(QString::fromStdString(backend ? backend->name() : "cpu")));
                             else if (job->state() == Job::State::Failed) fail(tr("Export failed"), job->error());
                             else log(tr("export cancelled"));
                         });
}

QString ExportController::gridFileBase(const QString& speciesName)
{
    return QString::fromStdString(sylva::gridFileBase(speciesName.toStdString()));
}

Job* ExportController::exportSpeciesGrids(int species, const QString& folder, GridFileFormat format)
{
    const Scene scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) {
        fail(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return nullptr;
    }
    const SpeciesDesc& sp = scene.species[size_t(species)];
    const std::string dir = folder.toStdString();
    const GridExportFiles files = gridExportFiles(dir, sp.name, format);
    AssetsPtr held = m_assets->find(assetKey(sp, scene, true));
    if (!held) held = m_assets->find(assetKey(sp, scene, false));
    GridCache* cache = m_cache;
    Backend* backend = m_backend;
    log(tr("exporting the grids of %1 to %2").arg(QString::fromStdString(sp.name), QDir::toNativeSeparators(folder)));
    return m_jobs->start(tr("Export grids of %1").arg(QString::fromStdString(sp.name)),
                         [scene, species, held, cache, backend, dir, format](Job& job, Progress& progress) {
                             JobLog log;
                             sylva::exportSpeciesGrids(scene, size_t(species), dir, cache, backend, &progress, &log,
                                                held ? &held->mesh : nullptr, format);
                             for (const std::string& line : speciesLogLines(scene.species[size_t(species)].name, log))
                                 job.log(QString::fromStdString(line));
                         },
                         [this, files](Job* job) {
                             if (job->state() == Job::State::Succeeded && files.density == files.lighting)
                                 log(tr("exported %1").arg(QString::fromStdString(files.density)));
                             else if (job->state() == Job::State::Succeeded)
                                 log(tr("exported %1 and %2").arg(QString::fromStdString(files.density),
                                                                  QString::fromStdString(files.lighting)));
                             else if (job->state() == Job::State::Failed) fail(tr("Export failed"), job->error());
                             else log(tr("grid export cancelled"));
                         });
}

Job* ExportController::exportGltf(const QString& path, const GltfExportOptions& options)
{
    if (!path.endsWith(QLatin1String(".glb"), Qt::CaseInsensitive)) {
        fail(tr("Export failed"), tr("A glTF export is a .glb file: %1").arg(path));
        return nullptr;
    }
    const Scene scene = m_doc->scene();
    const std::string file = path.toStdString();
    AssetStore* store = m_assets;
    GridCache* cache = m_cache;
    Backend* backend = m_backend;
    auto plan = std::make_shared<GltfPlan>();
    m_lastGltfPlan = plan;
    log(tr("exporting the scene as glTF to %1").arg(QDir::toNativeSeparators(path)));
    return m_jobs->start(tr("Export %1").arg(QFileInfo(path).fileName()),
                         [scene, file, store, cache, backend, options, plan](Job& job, Progress& progress) {
                             SubProgress assetsPart(&progress, 0.0, 0.5);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<AssetsPtr> shared = ensureAssets(
                                 scene, false, *store, cache, &assetsProgress, [&job](const std::string& line) { job.log(QString::fromStdString(line)); },
                                 backend);
                             std::vector<SpeciesAssets> assets;
                             for (const AssetsPtr& a : shared) assets.push_back(*a);
                             *plan = planGltfExport(scene, assets, options);
                             job.log(QString::fromStdString("glTF: " + plan->summary()));
                             SubProgress writePart(&progress, 0.5, 1.0);
                             Progress writeProgress([&](double f, const std::string& m) { writePart.report(f, m); });
                             *plan = sylva::exportGltf(scene, assets, file, options, &writeProgress);   // refuses above the limit
                         },
                         [this, path, plan](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 log(tr("exported %1: %2 (%3 bytes)")
                                         .arg(QDir::toNativeSeparators(path), QString::fromStdString(std::to_string(plan->instances) + " instances"))
                                         .arg(qint64(plan->estimatedBytes)));
                             else if (job->state() == Job::State::Failed) fail(tr("Export failed"), job->error());
                             else log(tr("glTF export cancelled"));
                         });
}

void ExportController::exportGltfDialog()
{
    const QString start = !lastFolder(QStringLiteral("gltf")).isEmpty() ? lastFolder(QStringLiteral("gltf"))
                          : m_doc->filePath().isEmpty()                  ? QString()
                                                                         : QFileInfo(m_doc->filePath()).absolutePath();
    QString path = QFileDialog::getSaveFileName(m_window, tr("Export Scene as glTF"), start + QStringLiteral("/scene.glb"),
                                                tr("Binary glTF (*.glb)"));
    if (path.isEmpty()) return;
    if (!path.endsWith(QLatin1String(".glb"), Qt::CaseInsensitive)) path += QStringLiteral(".glb");
    rememberFolder(QStringLiteral("gltf"), QFileInfo(path).absolutePath());
    GltfExportOptions options;
    options.instanceLimit = m_gltfInstanceLimit;
    options.byteLimit = m_gltfByteLimit;
    Job* job = exportGltf(path, options);
    if (!job) return;
    // Over the limit the job fails without writing; the user may then export anyway.
    connect(job, &Job::finished, this, [this, path](Job* done) {
        if (done->state() != Job::State::Failed || !m_lastGltfPlan->overLimit()) return;
        const auto answer = QMessageBox::question(m_window, tr("Export Scene as glTF"),
                                                  tr("The export holds %1.\nWrite it anyway?").arg(QString::fromStdString(m_lastGltfPlan->summary())));
        if (answer != QMessageBox::Yes) return;
        GltfExportOptions forced;
        forced.force = true;
        exportGltf(path, forced);
    });
}

void ExportController::exportDialog()
{
    ExportSettings initial = m_lastExport;
    if (initial.path.isEmpty()) {
        const Scene& s = m_doc->scene();
        initial.path = QFileInfo(m_doc->filePath().isEmpty() ? tr("render") : m_doc->filePath()).absolutePath() +
                       QStringLiteral("/render.png");
        initial.width = s.render.width;
        initial.height = s.render.height;
        initial.spp = std::max(1, s.render.spp);
    }
    ExportDialog d(initial, m_window);
    if (d.exec() == QDialog::Accepted) exportRender(d.settings());
}

void ExportController::exportGridsDialog(int species, GridFileFormat format)
{
    if (species < 0) {
        fail(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return;
    }
    const QString folder = QFileDialog::getExistingDirectory(
        m_window, tr("Export the grids of %1 to").arg(QString::fromStdString(m_doc->scene().species[size_t(species)].name)),
        !lastFolder(QStringLiteral("grids")).isEmpty() ? lastFolder(QStringLiteral("grids"))
        : m_doc->filePath().isEmpty()               ? QString()
                                                    : QFileInfo(m_doc->filePath()).absolutePath());
    if (folder.isEmpty()) return;
    rememberFolder(QStringLiteral("grids"), folder);
    exportSpeciesGrids(species, folder, format);
}

} // namespace sylva
