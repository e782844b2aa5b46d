// sylva sky: a Preetham sky (the sun from a scene file or --sun) written as an equirectangular map.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/image/image.h"
#include "core/sky/env_map.h"
#include "core/sky/preetham.h"
#include "core/sky/sun_position.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/image_io.h"
#include "pipeline/io/output_path.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"

namespace sylva::cli {
namespace {

int runSky(const Args& args)
{
    const std::string out = args.require("--output");
    const std::string ext = lowerExtension(out);
    if (ext != ".exr" && ext != ".hdr")
        throw UsageError("option --output: the sky is linear HDR radiance; write .exr (half float) or .hdr, got '" + out + "'");
    sky::PreethamParams params;
    if (!args.positional().empty()) {
        const std::string path = args.positional()[0];
        requireReadable(path, "scene file");
        params.sunDirection = readSceneFile(path).sun.direction;
    }
    if (args.has("--sun")) {
        if (args.get("--sun").find(',') == std::string::npos) throw UsageError("option --sun: expected X,Y,Z");
        params.sunDirection = parseTriple("--sun", args.get("--sun"));
        if (!(glm::length(params.sunDirection) > 0.0f)) throw UsageError("option --sun: the direction must not be zero");
    }
    if (args.has("--sun-at")) {
        if (args.has("--sun")) throw UsageError("give either --sun or --sun-at, not both");
        const sky::SunPosition pos = sky::noaaSunPosition(parseSunAt(args.get("--sun-at")));
        params.sunDirection = pos.direction;
        std::printf("sun at %s: elevation %.3f deg, azimuth %.3f deg (compass bearing %.3f deg; NOAA solar position)\n",
                    args.get("--sun-at").c_str(), pos.elevationDeg, pos.azimuthDeg, pos.compassAzimuthDeg);
    }
    if (args.has("--turbidity")) {
        params.turbidity = parseNumber("--turbidity", args.get("--turbidity"));
        if (params.turbidity < sky::kMinTurbidity || params.turbidity > sky::kMaxTurbidity)
            throw UsageError("option --turbidity: expected 2 .. 10, got " + args.get("--turbidity"));
    }
    if (args.has("--scale")) {
        const double s = parseNumber("--scale", args.get("--scale"));
        if (!(s >= 0.0) || s > 1e6) throw UsageError("option --scale: expected a number in 0 .. 1e6, got " + args.get("--scale"));
        params.scale = float(s);
    }
    const int width = args.has("--width") ? int(parseInteger("--width", args.get("--width"), 2, 16384)) : 512;
    if (width % 2 != 0) throw UsageError("option --width: a 2:1 map needs an even width, got " + args.get("--width"));
    const double elevation = std::asin(std::clamp(double(glm::normalize(params.sunDirection).y), -1.0, 1.0)) * 180.0 / sky::kPiD;
    if (elevation < sky::kMinSunElevationDeg - 1e-3)
        throw Error("the sun is " + std::to_string(-elevation) + " degrees below the horizon; the sky model covers down to -10");
    requireReplaceableFile(out);

    const sky::SkyView view = sky::preethamView(params, bundledCieTable());
    const sky::EnvMap map = sky::renderSkyToMap(view, width);
    ImageRgba img(map.width, map.height);
    float peak = 0.0f;
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const glm::vec3 c = map.at(x, y);
            float* p = img.at(x, y);
            p[0] = c.x, p[1] = c.y, p[2] = c.z, p[3] = 1.0f;
            peak = std::max({peak, c.x, c.y, c.z});
        }
    if (ext == ".exr" && peak > 65504.0f)
        throw Error("the brightest pixel (" + std::to_string(peak) + ") does not fit a half-float EXR; lower --scale");
    writeImage(out, img, 3);
    const glm::dvec3 total = sky::envMapIntegral(map), irr = sky::envMapUpperIrradiance(map);
    const glm::vec3 sunRgb = view.sun.radiance();
    std::printf("Preetham sky, turbidity %.2f, sun elevation %.2f deg: zenith luminance %.4g kcd/m^2 x scale %g\n"
                "sky on a horizontal plane %.4g (luminance of the upper hemisphere's cosine integral), whole sphere %.4g\n"
                "sun (not drawn in the map): %s, radiance (%.4g, %.4g, %.4g) = colour x %.4g klux x scale\n"
                "wrote %s (%d x %d, linear Rec. 709, row 0 at the zenith)\n",
                params.turbidity, elevation, double(view.preetham.zenith[0]), double(params.scale),
                0.2126 * irr.x + 0.7152 * irr.y + 0.0722 * irr.z, 0.2126 * total.x + 0.7152 * total.y + 0.0722 * total.z,
                view.sun.present ? "above the horizon" : "below the horizon", double(sunRgb.x), double(sunRgb.y), double(sunRgb.z),
                params.scale > 0.0f ? double(view.sun.illuminance / params.scale) : 0.0, out.c_str(), map.width, map.height);
    return kOk;
}

} // namespace

Command skyCommand()
{
    return {"sky", "[SCENE] [--turbidity T] [--sun X,Y,Z | --sun-at DATE,TIME,ZONE,LAT,LON] [--width W] -o SKY.exr",
            "a Preetham daylight sky as an equirectangular HDR map (2:1, row 0 at the zenith)",
            {{"--turbidity", "T", "atmospheric turbidity, 2 (clear) .. 10 (hazy); default 3"},
             {"--sun", "X,Y,Z", "direction toward the sun (+Y up), elevation >= -10 degrees; default: the scene's sun, "
                                "else (0.4, 0.8, 0.3). SCENE gives only the sun: its sky block (kind, turbidity) is not read"},
             kSunAt,
             {"--width", "W", "map width in pixels, even, 2 .. 16384 (height W/2); default 512"},
             {"--scale", "S", "multiplies the radiance (the model's unit is kcd/m^2); default 1"},
             kOutput},
            0, 1, &runSky};
}

} // namespace sylva::cli
