// `sylva render` as a library call: species meshes, textures and lighting grids for a scene, the frame, the picture.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/color/color.h"
#include "core/render/cryptomatte.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/display_view.h"

namespace sylva {

class Backend;
class GridCache;

// The CIE 1931 table bundled with the program (resources/color).
const CieTable& bundledCieTable();

// Linear RGB radiance of the scene's sun: blackbody colour (luminance 1) x intensity.
glm::vec3 sunRadiance(const SunDesc& sun);

// The bundled default forest (resources/default_forest.sylva.json): five grown broadleaf species,
// 962 instances, 896x448.
Scene defaultScene();

// What the renderer divides a species' or volume's LB grid by (SpeciesAssets / VolumeData lightingNorm): the
// sun's free-field total sum_m max(0, n_m . d) x params.intensity per channel, whatever else the boundary holds.
glm::vec3 sunFreeField(const lb::LbParams& params);

// The boundary weights of a species' LB solve when the scene asks for more than the sun (lighting.boundary
// sun_sky; params: the species' optics with the LB sun, lbSunDirection): the sun's weights x its radiance
// over lbRadiance, plus the sky's (lb::skyWeights, its sun kept apart) in units of pi x lbRadiance over the
// sun's free-field total, so that open space shows albedo x (fluence / pi) from the sky as from the sun
// (docs/RENDERING.md "The sky in the LB boundary"). nullopt: the sun alone (the seed's boundary, solved
// from params as always). Throws Error when the scene's sky needs building (loadSceneSky) and is not built.
std::optional<lb::BoundaryWeights> speciesBoundary(const Scene& scene, const lb::LbParams& params);

// What a species' lighting grid depends on beyond the species itself, as text (equal text, equal grids): the
// LB sun (lbSunDirection), lighting.direct and, with lighting.boundary sun_sky, the sky's settings and the
// frame sun's radiance. The studio keys its in-memory assets with it.
std::string speciesLightingKey(const Scene& scene);

// Whether a render mode uses the LB lighting grids (local does not: no grid is solved for it).
bool modeNeedsLighting(RenderMode mode);

// Loads or grows every species' mesh and textures, and (when needLighting) its density and lighting
// grids through the cache. Stages go to log as "SPECIES: grow|import", then the lighting job's stages.
// The LB solve uses the scene's sun in the species frame (instances share their species' grid).
std::vector<SpeciesAssets> loadSpeciesAssets(const Scene& scene, GridCache* cache, bool needLighting,
                                             Progress* progress = nullptr, JobLog* log = nullptr,
                                             Backend* backend = nullptr);

// The density and LB lighting grids of one species of a scene, through the same calls and cache keys
// as loadSpeciesAssets (a species the scene has lit is a cache hit): what the studio's volume
// inspector shows and its grid export writes.
struct SpeciesGrids {
    DensityGrid density;               // species frame (wood fraction included)
    LightingGrid lighting;             // species frame, photon density per node and channel
    lb::LbParams params;               // as solved: the species' parameters with the scene's sun
    glm::vec3 lightingNorm{1.0f};      // photon density of unobstructed space per channel
};
// species: index into scene.species. mesh: the species' mesh when it is already in memory (else it is
// grown or imported as loadSpeciesAssets does). Throws Error (bad index, unreadable mesh) or Cancelled.
SpeciesGrids loadSpeciesGrids(const Scene& scene, size_t species, GridCache* cache, Progress* progress = nullptr,
                              JobLog* log = nullptr, const TriangleMesh* mesh = nullptr, Backend* backend = nullptr);

// Timings of one render, seconds.
struct RenderTimings {
    double assets = 0.0, build = 0.0, trace = 0.0;
};

// Assets, acceleration structures and the film of a scene, with progress (assets 0-60%, build, trace).
struct RenderOutput {
    Film film;
    MatteFilm mattes;   // with `mattes`: the frame's camera samples by first hit (the Cryptomatte passes); else empty
    AccelStats stats;
    RenderTimings timings;
};
// backend: where the LB solves and the frame run (null = the CPU). The film holds every pixel until the
// picture is composed, so a frame needs about kFrameBytesPerPixel bytes per pixel (film + composed
// picture; 16384 x 8192 about 9 GB): one that does not fit in 80% of the available memory is refused
// up front (Error naming the size and the memory), before any asset is loaded.
// tracer: traces the frame's rows in place of the backend (sylva render --mpi hands them to the ranks as tiles).
// mattes: also renderMatteFilm of the frame on the CPU (its camera rays traced again to their first hits).
inline constexpr size_t kFrameBytesPerPixel = sizeof(SampleParts) + sizeof(glm::vec3);
// Rows y0 (inclusive) to y1 (exclusive) of scene.view() as a film: renderFilmRows's contract (the whole
// scene, not only its view: render --mpi sends the built scene to the other ranks). A frame's rows are
// traced once, top to bottom: the call whose rows end at the frame's last row is the frame's last.
using FilmRowsTracer = std::function<Film(const RenderScene& scene, int y0, int y1, Progress* progress)>;
RenderOutput renderScene(const Scene& scene, GridCache* cache, Progress* progress = nullptr, JobLog* log = nullptr,
                         Backend* backend = nullptr, const FilmRowsTracer& tracer = {}, bool mattes = false);

// The assets (0-60% of progress) and the acceleration structures (60-70%) of the scene's frame, the
// steps renderScene takes before tracing; timings.assets and timings.build are set.
RenderScene prepareRenderScene(const Scene& scene, GridCache* cache, Progress* progress, JobLog* log, Backend* backend,
                               RenderTimings& timings);

// Whether a whole frame (film and composed picture, kFrameBytesPerPixel per pixel) fits in 80% of the
// available memory (core/base/memory.h; true when unknown).
bool frameFitsMemory(const RenderSettings& r);

// Rows per band for renderSceneInBands: a band's film and pictures in about 256 MB (at most a quarter
// of the available memory), a multiple of 8, at least 8.
int bandRowsFor(const RenderSettings& r);

struct BandedRender {
    AccelStats stats;
    RenderTimings timings;
    float ambient = 0.0f;   // the ambient mode's constant (0 in other modes)
    int bands = 0, bandRows = 0;
};
// A frame too large to hold whole, traced on the CPU in bands of bandRows rows and written to outPath
// (.png/.tif/.tiff through the scene's view, .exr linear) band by band: memory holds one band, and between the
// passes the pixels wait in an unlinked temporary file beside outPath (12 bytes per pixel, 28 in
// ambient mode; refused up front, naming the sizes, when the disk lacks the room). The picture is
// exactly the one renderScene + composeMode + writeRender produce: the ambient constant and the
// log-average luminance sum the bands in the whole frame's order. Throws Error or Cancelled; the
// target file is only replaced at the end.
// backend: where the species' LB solves run (null = the CPU); the bands are traced on the CPU (by
// renderFilmRows, or by tracer when given).
BandedRender renderSceneInBands(const Scene& scene, const std::string& outPath, int bandRows, GridCache* cache,
                                Progress* progress = nullptr, JobLog* log = nullptr, Backend* backend = nullptr,
                                const FilmRowsTracer& tracer = {});

// Tone-mapped (Reinhard, log-average key) sRGB picture of linear RGB pixels, alpha 1; with a view, the picture
// exposed with the key through that display transform (displayEncode).
ImageRgba toneMapped(const std::vector<glm::vec3>& linear, int width, int height, float key);
ImageRgba toneMapped(const std::vector<glm::vec3>& linear, int width, int height, float key, const DisplayTransform& view);

// The display transform of a scene's render settings (render.display, render.view): DisplayTransform::find.
DisplayTransform displayTransformOf(const RenderSettings& r);

// Writes a render: .png/.tif/.tiff 8-bit through the view (default: Sylva Reinhard, the tone-mapped sRGB picture),
// .exr linear half float, its header naming the colour space (scene-linear Rec.709: chromaticities, colorInteropID
// lin_rec709_scene). Error on other extensions.
void writeRender(const std::string& path, const std::vector<glm::vec3>& linear, int width, int height, float key,
                 const DisplayTransform& view = DisplayTransform());

} // namespace sylva
