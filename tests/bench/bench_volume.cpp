// The cloud example's 640x480 frame (resources/cloud.sylva.json) on the CPU: trace time per volume tracer
// mode and step, and each one's image error against the Monte Carlo picture (core/reference's fluence
// of the same cloud marched along the camera rays at step 0.1 node). The picture's oracle is exact for
// isotropic scattering only, so the study runs the example with g = 0 (its other optics as the preset);
// the timings are those of the example itself (g = 0.9 costs the same).
//   bench_volume [SCENE] [--paths N (default 2M)] [--reps R (the default's frame, 3)] [--study-reps R (1)] [--frame-only]
// Ends with name=value lines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <numeric>
#include <string>
#include <vector>

#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"
#include "core/render/render_cpu.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/volume_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/bench/bench_timing.h"

using namespace sylva;

namespace {

// Over the pixels where mask is set (the volume changes them: the cloud and its shadow).
double relativeL2(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b, const std::vector<char>& mask)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3 && mask[i]; ++c) {
            num += std::pow(double(a[i][c]) - double(b[i][c]), 2);
            den += std::pow(double(b[i][c]), 2);
        }
    return std::sqrt(num / den);
}

} // namespace

int main(int argc, char** argv)
{
    std::string path = std::string(SYLVA_SOURCE_DIR) + "/resources/cloud.sylva.json";
    uint64_t paths = 2000000;
    int reps = 3, studyReps = 1;
    bool frameOnly = false;   // the default's frame and the frame without the cloud, no study
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--paths") && i + 1 < argc) paths = std::stoull(argv[++i]);
        else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::stoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--study-reps") && i + 1 < argc) studyReps = std::stoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--frame-only")) frameOnly = true;
        else path = argv[i];
    }
    Scene scene = readSceneFile(path);
    scene.render.width = 640;
    scene.render.height = 480;
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, nullptr, true);
    const glm::vec3 sun = sunRadiance(scene.sun);

    // The example as it is: the default's frame time, beside the same frame without the cloud.
    const Scene lit = lightSceneVolumes(scene, nullptr, true);
    const RenderScene rsDefault = buildRenderScene(lit, assets, sun);
    const bench::Timing tDefault = bench::timeReps(reps, [&] { (void)renderFilm(rsDefault.view()); });
    Scene noVolume = scene;
    noVolume.volumes.clear();
    const RenderScene rsPlain = buildRenderScene(noVolume, assets, sun);
    const bench::Timing tPlain = bench::timeReps(reps, [&] { (void)renderFilm(rsPlain.view()); });
    std::printf("640x480 frame of %s on the CPU: %.3f s with the cloud (tracer %s, step %.2g), %.3f s without it (median of %d)\n",
                path.c_str(), tDefault.median, volumeTracerName(scene.volumes[0].tracer), double(scene.volumes[0].step), tPlain.median,
                reps);
    std::fflush(stdout);
    if (frameOnly) {
        // The step's own error: each (step, shadow step) against the finest march the tracer does (step 0.5:
        // the optical-depth cap of kVolumeTauPerStep then sets every step in dense bricks), relative L2
        // over the pixels the cloud changes (itself and its shadow), with its frame time.
        double cpuSeconds = 0.0, plainCpu = 0.0;
        auto frame = [&](float step, float shadowStep, double* seconds) {
            Scene s = lit;
            s.volumes[0].step = step;
            s.volumes[0].shadowStep = shadowStep;
            const RenderScene r = buildRenderScene(s, assets, sun);
            Film film;
            const std::clock_t c0 = std::clock();
            const bench::Timing tm = bench::timeReps(reps, [&] { film = renderFilm(r.view()); });
            *seconds = tm.median;
            cpuSeconds = double(std::clock() - c0) / CLOCKS_PER_SEC / reps;   // both threads' work: steadier than wall under load
            return composeMode(film, RenderMode::Full, s.sky);
        };
        double sec = 0.0;
        const std::vector<glm::vec3> fine = frame(0.5f, 0.5f, &sec);
        const double fineCpu = cpuSeconds;
        {
            const std::clock_t c0 = std::clock();
            for (int k = 0; k < reps; ++k) (void)renderFilm(rsPlain.view());
            plainCpu = double(std::clock() - c0) / CLOCKS_PER_SEC / reps;
        }
        const std::vector<glm::vec3> plainPic = composeMode(renderFilm(rsPlain.view()), RenderMode::Full, scene.sky);
        std::vector<char> mask(fine.size());
        size_t changed = 0;
        for (size_t i = 0; i < fine.size(); ++i) changed += (mask[i] = fine[i] != plainPic[i]);
        std::printf("\nstep study (medians of %d; reference step 0.5, shadow step 0.5, %.3f s; %zu pixels changed by the cloud)\n"
                    "processor time without the cloud %.3f s, reference %.3f s\n"
                    "| step | shadow step | frame (s) | processor s | cloud's processor s | rel. L2 to the reference |\n| --- | --- | --- | --- | --- | --- |\n",
                    reps, sec, changed, plainCpu, fineCpu);
        std::string lines;
        for (auto [st, sh] : {std::pair{1.0f, 2.0f}, {2.0f, 2.0f}, {4.0f, 2.0f}, {4.0f, 4.0f}, {8.0f, 4.0f}, {8.0f, 8.0f}, {16.0f, 8.0f}}) {
            const double e = relativeL2(frame(st, sh, &sec), fine, mask);
            std::printf("| %.0f | %.0f | %.3f | %.3f | %.3f | %.5f |\n", double(st), double(sh), sec, cpuSeconds, cpuSeconds - plainCpu, e);
            std::fflush(stdout);
            char buf[160];
            std::snprintf(buf, sizeof buf, "step%.0f_shadow%.0f_s=%.4f\nstep%.0f_shadow%.0f_cpu_s=%.4f\nstep%.0f_shadow%.0f_err=%.5f\n", double(st),
                          double(sh), sec, double(st), double(sh), cpuSeconds, double(st), double(sh), e);
            lines += buf;
        }
        std::printf("\nframe_default_s=%.4f\nframe_no_volume_s=%.4f\n%s", tDefault.median, tPlain.median, lines.c_str());
        return 0;
    }

    // The study: the cloud with g = 0.
    Scene iso = scene;
    VolumeDesc& v = iso.volumes[0];
    for (auto& c : v.lighting.channels) c.g = 0.0f;
    v.lighting.zeroF0 = true;   // absorbed light is gone, as the tracer and the reference take it
    const Scene isoLit = lightSceneVolumes(iso, nullptr, true);
    const VolumeData& data = *isoLit.volumes[0].data;
    lb::LbParams p = volumeLightingParams(iso, v);
    ReferenceSettings rs;
    rs.paths = paths;
    rs.incidence = Incidence::Collimated;
    const double t0 = bench::now();
    ReferenceResult mc = solveReference(data.density, p, rs);
    normalizeToUnobstructed(mc.mean, p);
    std::printf("Monte Carlo reference: %llu paths in %.1f s, %.1f collisions a path, noise %.4f per node\n", (unsigned long long)paths,
                bench::now() - t0, mc.collisionsPerPath, relativeNoiseInterior(mc.mean, mc.standardError));
    std::fflush(stdout);

    auto picture = [&](VolumeTracer t, float step, bool reference, double* seconds) {
        Scene s = isoLit;
        VolumeDesc& vd = s.volumes[0];
        auto d = std::make_shared<VolumeData>(*vd.data);
        if (reference) {
            d->lighting = mc.mean;
            d->lightingNorm = glm::vec3(1.0f);
        }
        vd.data = d;
        vd.tracer = t;
        vd.step = step;
        vd.shadowStep = std::max(step, 0.1f);
        const RenderScene r = buildRenderScene(s, assets, sun);
        Film film;
        const bench::Timing tm = bench::timeReps(reference ? 1 : studyReps, [&] { film = renderFilm(r.view()); });
        if (seconds) *seconds = tm.median;
        return composeMode(film, RenderMode::Full, s.sky);
    };
    const std::vector<glm::vec3> ref = picture(VolumeTracer::Lb, 0.1f, true, nullptr);
    const std::vector<glm::vec3> plain = composeMode(renderFilm(rsPlain.view()), RenderMode::Full, scene.sky);
    std::vector<char> mask(ref.size());
    size_t changed = 0;
    for (size_t i = 0; i < ref.size(); ++i) changed += (mask[i] = ref[i] != plain[i]);
    std::printf("pixels the cloud changes (itself and its shadow): %zu of %zu\n", changed, ref.size());
    std::printf("\n| tracer | step (nodes) | frame (s) | error to MC (rel. L2) |\n| --- | --- | --- | --- |\n");
    std::vector<std::string> lines;
    for (VolumeTracer t : {VolumeTracer::Lb, VolumeTracer::Combined, VolumeTracer::Single})
        for (float step : {0.5f, 1.0f, 2.0f, 4.0f}) {
            double sec = 0.0;
            const double e = relativeL2(picture(t, step, false, &sec), ref, mask);
            std::printf("| %s | %.1f | %.3f | %.4f |\n", volumeTracerName(t), double(step), sec, e);
            std::fflush(stdout);
            char buf[160];
            std::snprintf(buf, sizeof buf, "%s_step%.1f_s=%.4f\n%s_step%.1f_err=%.4f\n", volumeTracerName(t), double(step), sec,
                          volumeTracerName(t), double(step), e);
            lines.push_back(buf);
        }
    std::printf("\nframe_default_s=%.4f\nframe_no_volume_s=%.4f\n", tDefault.median, tPlain.median);
    for (const std::string& l : lines) std::printf("%s", l.c_str());
    return 0;
}
