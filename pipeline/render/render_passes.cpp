// Render passes (render_passes.h).
#include "pipeline/render/render_passes.h"

#include "core/base/error.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/image_io.h"

namespace sylva {

namespace {

// A part that includes the surface colour, divided by it per channel (Cycles' "divide by colour"):
// diffCol * result gives the part back to float rounding. A channel whose colour is 0 holds 0.
glm::vec3 divideByColour(const glm::vec3& part, const glm::vec3& colour)
{
    glm::vec3 out(0.0f);
    for (int c = 0; c < 3; ++c) out[c] = colour[c] > 0.0f ? part[c] / colour[c] : 0.0f;
    return out;
}

} // namespace

RenderPasses renderPasses(const Film& film, RenderMode mode, const glm::vec3& sky)
{
    RenderPasses out;
    out.width = film.width;
    out.height = film.height;
    out.combined = composeMode(film, mode, sky, &out.ambient);
    const float ambient = out.ambient;
    const size_t n = film.pixels.size();
    for (auto* layer : {&out.diffDir, &out.diffInd, &out.diffCol, &out.env, &out.normal}) layer->resize(n);
    out.depth.resize(n);
    out.alpha.resize(n);
    const bool direct = mode != RenderMode::Lb;
    for (size_t i = 0; i < n; ++i) {
        const SampleParts& p = film.pixels[i];
        glm::vec3 indirect(0.0f);
        if (mode == RenderMode::Full || mode == RenderMode::Lb) indirect = p.indirect;
        else if (mode == RenderMode::Ambient) indirect = ambient * p.albedo;
        out.diffDir[i] = direct ? divideByColour(p.local, p.albedo) : glm::vec3(0.0f);
        out.diffInd[i] = divideByColour(indirect, p.albedo);
        out.diffCol[i] = p.albedo;
        out.env[i] = p.skyCover * sky + p.background;
        out.normal[i] = p.normal;
        out.depth[i] = p.depth;
        out.alpha[i] = 1.0f - p.skyCover;
    }
    return out;
}

const std::vector<std::string>& renderPassChannels()
{
    static const std::vector<std::string> names = {
        "Combined.R", "Combined.G", "Combined.B", "DiffDir.R", "DiffDir.G", "DiffDir.B", "DiffInd.R", "DiffInd.G",
        "DiffInd.B",  "DiffCol.R",  "DiffCol.G",  "DiffCol.B", "Env.R",     "Env.G",     "Env.B",     "Normal.X",
        "Normal.Y",   "Normal.Z",   "Depth.Z",    "Alpha.A"};
    return names;
}

void writeRenderPasses(const std::string& path, const RenderPasses& passes)
{
    if (lowerExtension(path) != ".exr") throw Error(path + ": render passes are written as a multi-layer OpenEXR file (use .exr)");
    const size_t n = size_t(passes.width) * size_t(passes.height);
    const std::vector<std::string>& names = renderPassChannels();
    std::vector<float> data(n * names.size());
    for (size_t i = 0; i < n; ++i) {
        float* d = &data[i * names.size()];
        for (const glm::vec3* layer : {&passes.combined[i], &passes.diffDir[i], &passes.diffInd[i], &passes.diffCol[i],
                                       &passes.env[i], &passes.normal[i]}) {
            d[0] = layer->x, d[1] = layer->y, d[2] = layer->z;
            d += 3;
        }
        d[0] = passes.depth[i];
        d[1] = passes.alpha[i];
    }
    writeImageChannels(path, passes.width, passes.height, names, data);
}

} // namespace sylva
