// The CPU render loop over 8x8 pixel tiles, the film of shading parts, and how render modes combine them.
#pragma once

#include <vector>

#include "core/base/progress.h"
#include "core/render/render_view.h"
#include "core/render/shade.h"

namespace sylva {

// Per-pixel shading parts of a frame, row-major, top row first.
struct Film {
    int width = 0, height = 0;
    std::vector<SampleParts> pixels;
};

// Traces every pixel of v.width x v.height with v.spp samples, in parallel over 8x8 tiles (a landscape's
// camera rays and their sun shadow rays a tile at a time as packets, core/render/trace_packet.h).
// Reports progress per tile row; throws Cancelled when cancelled.
Film renderFilm(const RenderView& v, Progress* progress = nullptr);

// Rows y0 (inclusive) to y1 (exclusive) of the same frame: exactly the pixels renderFilm computes for
// those rows (a frame too large to hold whole is rendered in bands). film.height = y1 - y0.
Film renderFilmRows(const RenderView& v, int y0, int y1, Progress* progress = nullptr);

// The rectangle [x0, x1) x [y0, y1) of the frame (frame pixels) into out, row-major, (x1 - x0) x (y1 - y0)
// parts: exactly the pixels renderFilm computes there (shadePixel's parts per pixel, a landscape's 8x8 tiles
// traced as packets with the same answers; nothing depends on the rectangle), in parallel over its tiles. The tiles of `sylva render --mpi` (pipeline/mpi). Throws Error
// for a rectangle outside the frame.
void renderFilmRect(const RenderView& v, int x0, int y0, int x1, int y1, SampleParts* out);

// Progressive refinement (the studio viewport once the camera stops; the same samples `sylva render
// --spp` traces at once): `sum` holds the mean of sumSamples samples per pixel, `part` the mean of
// partSamples further ones (a frame of RenderView::sampleBegin .. sampleEnd); sum becomes the mean of
// all of them (depth: the nearest). An empty sum (sumSamples 0) becomes part. Throws Error for films of
// different sizes.
void accumulateFilm(Film& sum, int sumSamples, const Film& part, int partSamples);

// The sums ambient mode matches (luminance of indirect and of albedo over the film's pixels, in pixel
// order), added to *indirect and *albedo so a frame in bands sums exactly as the whole film does.
void addAmbientSums(const Film& film, double* indirect, double* albedo);
// The ambient constant from those sums over the whole frame.
SYLVA_HD inline float ambientConstant(double indirect, double albedo) { return albedo > 0.0 ? float(indirect / albedo) : 0.0f; }

// Linear RGB of a render mode: full = local + indirect, local = sun light only, ambient = local + a
// constant ambient x albedo with the constant chosen so the mean luminance equals that of full,
// lb = indirect only; the sky is added where samples saw it. ambientOut receives the constant.
std::vector<glm::vec3> composeMode(const Film& film, RenderMode mode, const glm::vec3& sky, float* ambientOut = nullptr);

} // namespace sylva
