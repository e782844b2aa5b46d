// sylva simulate: a smoke simulation (core/volume/smoke.h) writing density (and temperature) frames.
#include <cstdio>
#include <string>

#include "core/base/progress.h"
#include "core/volume/smoke.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/param_options.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"

namespace sylva::cli {
namespace {

// How often a frame is written: a choice of this command alone.
constexpr ParamSpec kEvery{.key = "every", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 1, .hi = 1000000, .def = {10},
                           .help = "write a frame every N steps and after the last"};

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
    readParam(args, volume::kSmokeCells, s.cells);
    float width = float(volume::kSmokeWidth.def[0]);
    readParam(args, volume::kSmokeWidth, width);
    volume::setSmokeDomain(s, width);
    readParam(args, volume::kSmokeDt, s.dt);
    int steps = int(volume::kSmokeSteps.def[0]);
    readParam(args, volume::kSmokeSteps, steps);
    checkParam(volume::kSmokeSteps, steps, "simulate");
    int every = int(kEvery.def[0]);
    readParam(args, kEvery, every);
    checkParam(kEvery, every, "simulate");
    glm::vec2 buoyancy(s.buoyancyDensity, s.buoyancyTemperature);
    if (readParam(args, volume::kSmokeBuoyancy, buoyancy)) {
        s.buoyancyDensity = buoyancy.x;
        s.buoyancyTemperature = buoyancy.y;
    }
    readParam(args, volume::kSmokeVorticity, s.vorticity);
    readParam(args, volume::kSmokeJitter, s.jitter);
    if (args.has("--cubic")) s.interp = volume::SmokeInterp::MonotonicCubic;
    readParam(args, volume::kSmokeTolerance, s.pressureTolerance);
    readParam(args, volume::kSmokeSeed, s.seed);
    std::vector<volume::SmokeShape> sources = args.has("--source") ? parseShapes("--source", args.get("--source"))
                                                                   : std::vector<volume::SmokeShape>{};
    if (!args.has("--source")) sources.push_back(volume::defaultSmokeSource(s, width));   // one sphere at the bottom centre
    volume::SmokeSource source;
    readParam(args, volume::kSmokeSourceDensity, source.density);
    readParam(args, volume::kSmokeSourceTemperature, source.temperature);
    readParam(args, volume::kSmokeSourceVelocity, source.velocity);
    for (const volume::SmokeShape& sh : sources) {
        source.shape = sh;
        s.sources.push_back(source);
    }
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
    using namespace volume;
    const std::string cfl = "; a step that moves anything more than " + paramNumber(SmokeSettings{}.cflLimit) + " cells (the CFL limit) is refused";
    return {"simulate", "[options] -o SMOKE.npy|.vdb",
            "simulate smoke (stable fluids, vorticity confinement) and write density frames SMOKE_NNNN.npy",
            {paramOption(kSmokeCells),
             paramOption(kSmokeWidth),
             paramOption(kSmokeDt, cfl),
             paramOption(kSmokeSteps),
             paramOption(kEvery),
             paramOption(kSmokeBuoyancy),
             paramOption(kSmokeVorticity),
             paramOption(kSmokeJitter),
             {"--cubic", "", "monotonic tricubic interpolation in the advection (default trilinear)"},
             paramOption(kSmokeTolerance),
             paramOption(kSmokeSeed),
             {"--source", "X,Y,Z,R;...", "source spheres (or box:X,Y,Z,HX,HY,HZ), metres; default one at the bottom centre"},
             paramOption(kSmokeSourceDensity),
             paramOption(kSmokeSourceTemperature),
             paramOption(kSmokeSourceVelocity),
             {"--obstacle", "X,Y,Z,R;...", "obstacle spheres (or box:X,Y,Z,HX,HY,HZ), metres"},
             {"--temperature", "", "also write temperature frames SMOKE_NNNN.temperature.npy"},
             kOutput, kThreads, kQuiet},
            0, 0, &runSimulate};
}

} // namespace sylva::cli
