// sylva simulate: a smoke simulation (core/volume/smoke.h) writing density (and temperature) frames.
#include <cstdio>
#include <string>

#include "core/base/progress.h"
#include "core/volume/smoke.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"

namespace sylva::cli {
namespace {

// "x,y,z,r" a sphere, "box:x,y,z,hx,hy,hz" a box; several separated by ';'.
std::vector<volume::SmokeShape> parseShapes(const std::string& option, const std::string& text)
{
    std::vector<volume::SmokeShape> shapes;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t end = std::min(text.find(';', start), text.size());
        std::string item = text.substr(start, end - start);
        start = end + 1;
        if (item.empty()) continue;
        volume::SmokeShape s;
        const bool box = item.rfind("box:", 0) == 0;
        if (box) item = item.substr(4);
        const std::vector<std::string> parts = splitList(item);
        std::vector<float> v;
        for (const std::string& p : parts) v.push_back(float(parseNumber(option, p)));
        if (box) {
            if (v.size() != 6) throw UsageError("option " + option + ": a box is box:X,Y,Z,HX,HY,HZ, got '" + item + "'");
            s.kind = volume::SmokeShape::Kind::Box;
            s.centre = {v[0], v[1], v[2]};
            s.halfSize = {v[3], v[4], v[5]};
        } else {
            if (v.size() != 4) throw UsageError("option " + option + ": a sphere is X,Y,Z,R, got '" + item + "'");
            s.centre = {v[0], v[1], v[2]};
            s.radius = v[3];
        }
        shapes.push_back(s);
    }
    return shapes;
}

// "smoke.npy", 12 -> "smoke_0012.npy"; suffix ".temperature" -> "smoke_0012.temperature.npy".
std::string framePath(const std::string& out, int frame, const char* suffix)
{
    const std::string ext = out.substr(out.size() - lowerExtension(out).size());
    char digits[16];
    std::snprintf(digits, sizeof digits, "_%04d", frame);
    return out.substr(0, out.size() - ext.size()) + digits + suffix + ext;
}

int runSimulate(const Args& args)
{
    auto threads = threadLimit(args);
    volume::SmokeSettings s;
    if (args.has("--grid")) {
        const std::vector<std::string> parts = splitList(args.get("--grid"));
        if (parts.size() != 3) throw UsageError("option --grid: expected X,Y,Z cells, got '" + args.get("--grid") + "'");
        for (int a = 0; a < 3; ++a) s.cells[a] = int(parseInteger("--grid", parts[size_t(a)], 0, 1 << 20));
    }
    const float width = args.has("--size") ? float(parseNumber("--size", args.get("--size"))) : 1.0f;
    if (!(width > 0.0f)) throw Error("simulate: --size " + args.get("--size") + " must be > 0");
    volume::setSmokeDomain(s, width);
    if (args.has("--dt")) s.dt = float(parseNumber("--dt", args.get("--dt")));
    const int steps = args.has("--steps") ? int(parseInteger("--steps", args.get("--steps"), 1, 1000000)) : 100;
    const int every = args.has("--every") ? int(parseInteger("--every", args.get("--every"), 1, 1000000)) : 10;
    if (args.has("--buoyancy")) {
        const glm::vec3 b = parseTriple("--buoyancy", args.get("--buoyancy") + ",0");
        s.buoyancyDensity = b.x;
        s.buoyancyTemperature = b.y;
    }
    if (args.has("--vorticity")) s.vorticity = float(parseNumber("--vorticity", args.get("--vorticity")));
    if (args.has("--jitter")) s.jitter = float(parseNumber("--jitter", args.get("--jitter")));
    if (args.has("--cubic")) s.interp = volume::SmokeInterp::MonotonicCubic;
    if (args.has("--tol")) s.pressureTolerance = parseNumber("--tol", args.get("--tol"));
    if (args.has("--seed")) s.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (1ll << 62)));
    std::vector<volume::SmokeShape> sources = args.has("--source") ? parseShapes("--source", args.get("--source"))
                                                                   : std::vector<volume::SmokeShape>{};
    if (!args.has("--source")) sources.push_back(volume::defaultSmokeSource(s, width));   // one sphere at the bottom centre
    const float sourceDensity = args.has("--source-density") ? float(parseNumber("--source-density", args.get("--source-density"))) : 1.0f;
    const float sourceTemp = args.has("--source-temperature") ? float(parseNumber("--source-temperature", args.get("--source-temperature"))) : 1.0f;
    const glm::vec3 sourceVel = args.has("--source-velocity") ? parseTriple("--source-velocity", args.get("--source-velocity")) : glm::vec3(0.0f);
    for (const volume::SmokeShape& sh : sources) s.sources.push_back({sh, sourceDensity, sourceTemp, sourceVel});
    if (args.has("--obstacle")) s.obstacles = parseShapes("--obstacle", args.get("--obstacle"));
    const bool writeTemperature = args.has("--temperature");
    const std::string out = outputFile(args, gridFileExtensions());
    volume::validateSmoke(s);   // sizes, memory, CFL of the sources: exit 1 before any work
    requireReplaceableFile(framePath(out, steps, ""));

    ProgressPrinter bar("simulate", args.has("--quiet"));
    volume::SmokeSim sim(s);
    int frames = 0;
    double iterations = 0.0;
    for (int n = 1; n <= steps; ++n) {
        sim.step(&bar.progress());
        iterations += sim.lastStats().pressureIterations;
        if (n % every == 0 || n == steps) {
            const int frame = n;
            writeDensityFile(framePath(out, frame, ""), sim.densityGrid());
            if (writeTemperature) writeDensityFile(framePath(out, frame, ".temperature"), sim.temperatureGrid());
            ++frames;
        }
        bar.progress().report(double(n) / double(steps), "step " + std::to_string(n) + "/" + std::to_string(steps));
    }
    bar.finish();
    std::printf("simulated %d steps of %dx%dx%d cells (dt %.4g s, cell %.4g m): %.1f pressure iterations per step, "
                "last divergence %.3g of before, max speed %.4g m/s\n",
                steps, s.cells.x, s.cells.y, s.cells.z, double(s.dt), double(s.cellSize), iterations / steps,
                sim.lastStats().divergenceBefore > 0 ? sim.lastStats().divergenceAfter / sim.lastStats().divergenceBefore : 0.0,
                sim.lastStats().maxSpeed);
    std::printf("wrote %d frames %s .. %s%s\n", frames, framePath(out, std::min(every, steps), "").c_str(), framePath(out, steps, "").c_str(),
                writeTemperature ? " (+ temperature)" : "");
    return kOk;
}

} // namespace

Command simulateCommand()
{
    return {"simulate", "[options] -o SMOKE.npy|.vdb",
            "simulate smoke (stable fluids, vorticity confinement) and write density frames SMOKE_NNNN.npy",
            {{"--grid", "X,Y,Z", "cells per axis, 3..512 each (default 64,96,64)"},
             {"--size", "W", "domain width along x, metres (default 1); cells are cubes"},
             {"--dt", "S", "time step, seconds (default 0.02); a step over the CFL limit 5 is refused"},
             {"--steps", "N", "steps to run (default 100)"},
             {"--every", "N", "write a frame every N steps and after the last (default 10)"},
             {"--buoyancy", "A,B", "force per unit density (down) and temperature (up), m/s^2 (default 0.05,2)"},
             {"--vorticity", "E", "vorticity confinement epsilon, 0 = off (default 0.3)"},
             {"--jitter", "J", "source density noise in [0, 1] (default 0.2)"},
             {"--cubic", "", "monotonic tricubic interpolation in the advection (default trilinear)"},
             {"--tol", "T", "relative residual of the pressure solve (default 1e-6)"},
             {"--seed", "N", "seed of the source noise (default 1); the same seed gives the same bits"},
             {"--source", "X,Y,Z,R;...", "source spheres (or box:X,Y,Z,HX,HY,HZ), metres; default one at the bottom centre"},
             {"--source-density", "D", "density the sources set, [0, 1] (default 1)"},
             {"--source-temperature", "T", "temperature the sources set (default 1)"},
             {"--source-velocity", "X,Y,Z", "velocity inside the sources, m/s (default 0)"},
             {"--obstacle", "X,Y,Z,R;...", "obstacle spheres (or box:X,Y,Z,HX,HY,HZ), metres"},
             {"--temperature", "", "also write temperature frames SMOKE_NNNN.temperature.npy"},
             kOutput, kThreads, kQuiet},
            0, 0, &runSimulate};
}

} // namespace sylva::cli
