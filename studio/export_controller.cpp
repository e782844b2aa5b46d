// ExportController: render and grid exports through the pipeline's export services, in jobs.
#include "studio/export_controller.h"

#include <algorithm>

#include <QDir>
#include <QFileDialog>
#include <QFileInfo>

#include "core/backend/backend.h"
#include "pipeline/render/render_job.h"
#include "pipeline/services/exports.h"
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
                             const bool lit = modeNeedsLighting(scene.render.mode);
                             SubProgress assetsPart(&progress, 0.0, 0.4);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<AssetsPtr> shared = ensureAssets(
                                 scene, lit, *store, cache, &assetsProgress,
                                 [&job](const std::string& line) { job.log(QString::fromStdString(line)); }, backend);
                             std::vector<SpeciesAssets> assets;
                             for (const AssetsPtr& a : shared) assets.push_back(*a);
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
