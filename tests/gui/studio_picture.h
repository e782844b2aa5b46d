// The studio tests' oracle for pictures: what the renderer itself gives for a scene and camera
// (buildRenderScene + renderFilm, as `sylva render` and the exports trace it), and how far a picture
// the window shows or writes is from it.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <vector>

#include <QImage>
#include <QSize>

#include "core/render/render_cpu.h"
#include "core/scene/scene.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "studio/asset_store.h"
#include "studio/render_worker.h"

namespace sylva::test {

// The assets the window holds for a scene, as buildRenderScene takes them.
inline std::vector<SpeciesAssets> assetCopies(const std::vector<AssetsPtr>& held)
{
    std::vector<SpeciesAssets> out;
    for (const AssetsPtr& a : held) out.push_back(*a);
    return out;
}

// The film of the viewport's first pass for `scene` at `size`, traced headless: the schedule's first pass (a
// quarter-size frame at its samples, every light on), whose exposure the viewport keeps for all its pictures
// of a view (RefineSettings::steady).
inline Film firstPassFilm(Scene scene, const std::vector<SpeciesAssets>& assets, QSize size)
{
    const RenderPass first = RenderWorker::defaultPasses().front();
    scene.render.width = std::max(1, size.width() / first.divisor);
    scene.render.height = std::max(1, size.height() / first.divisor);
    scene.render.spp = first.spp;
    return renderFilm(buildRenderScene(scene, assets, sunRadiance(scene.sun)).view());
}

// The settled picture of the CPU viewport for `scene` at `size`, traced headless: the frame `sylva render`
// builds for the scene's camera at that size, at the samples the viewport ends on (the schedule's last
// pass, or the refinement's accumulated samples for a sky with virtual lights or a sample limit above the last
// pass's: refinementFor), tone-mapped at the viewport's exposure, the first pass's (heldExposureImage of
// firstPassFilm). sampleLimit: the viewport's (0: the scene's spp, what the tests' settings hold).
inline QImage settledPicture(Scene scene, const std::vector<SpeciesAssets>& assets, QSize size, int sampleLimit = 0)
{
    const Film exposure = firstPassFilm(scene, assets, size);
    scene.render.width = size.width();
    scene.render.height = size.height();
    const int sceneSpp = scene.render.spp, lastPass = RenderWorker::defaultPasses().back().spp;
    scene.render.spp = lastPass;
    RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    const Refinement r = refinementFor(rs.view(), sceneSpp, lastPass, sampleLimit);
    if (r.frames > 0 && r.samples != lastPass) {
        scene.render.spp = r.samples;
        rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    }
    return heldExposureImage(renderFilm(rs.view()), exposure, scene.render.mode, scene.render.mode, composeSky(scene),
                             scene.render.exposureKey);
}

// Each pixel's largest channel difference between two pictures of one size, in 8-bit steps.
inline std::vector<int> pixelSteps(const QImage& p, const QImage& q)
{
    const QImage a = p.convertToFormat(QImage::Format_RGB32), b = q.convertToFormat(QImage::Format_RGB32);
    std::vector<int> steps;
    steps.reserve(size_t(a.width()) * size_t(a.height()));
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            const QRgb u = a.pixel(x, y), v = b.pixel(x, y);
            steps.push_back(std::max({std::abs(qRed(u) - qRed(v)), std::abs(qGreen(u) - qGreen(v)), std::abs(qBlue(u) - qBlue(v))}));
        }
    return steps;
}

// The largest difference of two pictures in any channel, in 8-bit steps (256: sizes differ).
inline int maxStep(const QImage& p, const QImage& q)
{
    if (p.size() != q.size()) return 256;
    const std::vector<int> s = pixelSteps(p, q);
    return s.empty() ? 0 : *std::max_element(s.begin(), s.end());
}

// Pixels whose largest channel difference exceeds `steps` 8-bit steps (every pixel: sizes differ).
inline int pixelsOver(const QImage& p, const QImage& q, int steps)
{
    if (p.size() != q.size()) return p.width() * p.height();
    const std::vector<int> s = pixelSteps(p, q);
    return int(std::count_if(s.begin(), s.end(), [steps](int d) { return d > steps; }));
}

} // namespace sylva::test
