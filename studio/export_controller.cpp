// ExportController: render and grid exports through the pipeline's calls, in jobs.
#include "studio/export_controller.h"

#include <algorithm>

#include <QDir>
#include <QFileDialog>
#include <QFileInfo>

#include "core/render/render_cpu.h"
#include "pipeline/io/npy.h"
#include "pipeline/render/render_job.h"
#include "studio/asset_store.h"
#include "studio/job_manager.h"
#include "studio/scene_document.h"

namespace sylva {

ExportController::ExportController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache,
                                   QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_jobs(jobs), m_assets(assets), m_cache(cache), m_window(window)
{
}

Job* ExportController::exportRender(const ExportSettings& settings)
{
    Scene scene = m_doc->scene();
    if (scene.instances.empty()) {
        fail(tr("Export failed"), tr("The scene is empty."));
        return nullptr;
    }
    scene.render.width = settings.width;
    scene.render.height = settings.height;
    scene.render.spp = settings.spp;
    m_lastExport = settings;
    const std::string path = settings.path.toStdString();
    GridCache* cache = m_cache;
    AssetStore* store = m_assets;
    log(tr("exporting %1 (%2 x %3, %4 spp)").arg(settings.path).arg(settings.width).arg(settings.height).arg(settings.spp));
    return m_jobs->start(tr("Export %1").arg(QFileInfo(settings.path).fileName()),
                         [scene, path, store, cache](Job& job, Progress& progress) {
                             const bool lit = modeNeedsLighting(scene.render.mode);
                             SubProgress assetsPart(&progress, 0.0, 0.4);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<AssetsPtr> shared = ensureAssets(
                                 scene, lit, *store, cache, &assetsProgress,
                                 [&job](const std::string& line) { job.log(QString::fromStdString(line)); });
                             std::vector<SpeciesAssets> assets;
                             for (const AssetsPtr& a : shared) assets.push_back(*a);
                             progress.report(0.45, "building");
                             const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
                             SubProgress tracePart(&progress, 0.5, 0.98);
                             Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
                             const Film film = renderFilm(rs.view(), &traceProgress);
                             const std::vector<glm::vec3> linear = composeMode(film, scene.render.mode, scene.sky);
                             writeRender(path, linear, film.width, film.height, scene.render.exposureKey);
                             progress.report(1.0, "written");
                         },
                         [this, settings](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 log(tr("exported %1 in %2 s").arg(settings.path).arg(job->seconds(), 0, 'f', 2));
                             else if (job->state() == Job::State::Failed) fail(tr("Export failed"), job->error());
                             else log(tr("export cancelled"));
                         });
}

QString ExportController::gridFileBase(const QString& speciesName)
{
    QString out;
    for (QChar c : speciesName)
        out += (c.isLetterOrNumber() && c.unicode() < 128) || c == u'.' || c == u'-' || c == u'_' ? c : QChar(u'_');
    return out.isEmpty() ? QStringLiteral("species") : out;
}

Job* ExportController::exportSpeciesGrids(int species, const QString& folder)
{
    const Scene scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) {
        fail(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return nullptr;
    }
    const SpeciesDesc& sp = scene.species[size_t(species)];
    const QString base = QDir(folder).filePath(gridFileBase(QString::fromStdString(sp.name)));
    const std::string densityPath = (base + QStringLiteral(".density.npy")).toStdString();
    const std::string lightingPath = (base + QStringLiteral(".lighting.npy")).toStdString();
    AssetsPtr held = m_assets->find(assetKey(sp, scene.sun, true));
    if (!held) held = m_assets->find(assetKey(sp, scene.sun, false));
    GridCache* cache = m_cache;
    log(tr("exporting the grids of %1 to %2").arg(QString::fromStdString(sp.name), QDir::toNativeSeparators(folder)));
    return m_jobs->start(tr("Export grids of %1").arg(QString::fromStdString(sp.name)),
                         [scene, species, held, cache, densityPath, lightingPath](Job& job, Progress& progress) {
                             const SpeciesDesc& d = scene.species[size_t(species)];
                             SubProgress loadPart(&progress, 0.0, 0.9);
                             Progress loadProgress([&](double f, const std::string& m) { loadPart.report(f, m); });
                             JobLog log;
                             const SpeciesGrids g = loadSpeciesGrids(scene, size_t(species), cache, &loadProgress, &log,
                                                                     held ? &held->mesh : nullptr);
                             for (const std::string& stage : log.stages)
                                 job.log(QString::fromStdString(stage.rfind(d.name + ":", 0) == 0 ? stage : d.name + ": " + stage));
                             progress.report(0.9, "writing");
                             writeDensityGrid(densityPath, g.density);
                             writeLightingGrid(lightingPath, g.lighting, lightingParamsJson(g.params, d.preset, g.lighting.geometry.dims));
                             progress.report(1.0, "written");
                         },
                         [this, densityPath, lightingPath](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 log(tr("exported %1 and %2").arg(QString::fromStdString(densityPath), QString::fromStdString(lightingPath)));
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

void ExportController::exportGridsDialog(int species)
{
    if (species < 0) {
        fail(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return;
    }
    const QString folder = QFileDialog::getExistingDirectory(
        m_window, tr("Export the grids of %1 to").arg(QString::fromStdString(m_doc->scene().species[size_t(species)].name)),
        m_doc->filePath().isEmpty() ? QString() : QFileInfo(m_doc->filePath()).absolutePath());
    if (!folder.isEmpty()) exportSpeciesGrids(species, folder);
}

} // namespace sylva
