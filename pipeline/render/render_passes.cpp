// Render passes (render_passes.h).
#include "pipeline/render/render_passes.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include "core/base/error.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/image_io.h"
#include "pipeline/scene/json_codec.h"

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

std::string rankLayerName(const std::string& type, int layer)
{
    char digits[16];
    std::snprintf(digits, sizeof digits, "%02d", layer);
    return type + digits;
}

} // namespace

MatteNames matteNames(const MatteHit& hit, const Scene& scene)
{
    const auto speciesName = [&](uint32_t s) { return s < scene.species.size() ? scene.species[s].name : "species " + std::to_string(s); };
    MatteNames n;
    switch (SurfaceKind(hit.kind)) {
    case SurfaceKind::Ground: n.object = n.material = n.asset = "ground"; break;
    case SurfaceKind::Terrain: n.object = n.material = n.asset = "terrain"; break;
    case SurfaceKind::Spheres:
        n.object = "sphere." + std::to_string(hit.object);
        n.material = n.asset = "sphere";
        break;
    case SurfaceKind::Instances:
    case SurfaceKind::Landscape: {
        const std::string species = speciesName(hit.species);
        if (SurfaceKind(hit.kind) == SurfaceKind::Landscape) {
            n.object = species + ".landscape." + std::to_string(hit.object) + "." + std::to_string(hit.plant);
        } else {
            const bool group = hit.object < scene.instances.size() && scene.instances[hit.object].group != kNoGroup &&
                               scene.instances[hit.object].group < scene.groups.size();
            n.object = (group ? scene.groups[scene.instances[hit.object].group].name : species) + "." + std::to_string(hit.object);
        }
        n.material = species + (hit.leaf ? "/leaf" : "/bark");
        n.asset = species;
        break;
    }
    case SurfaceKind::None: break;
    }
    return n;
}

std::vector<CryptomatteLayer> cryptomatteLayers(const MatteFilm& film, const Scene& scene)
{
    std::vector<MatteNames> names;
    names.reserve(film.hits.size());
    for (const MatteHit& h : film.hits) names.push_back(matteNames(h, scene));
    std::vector<CryptomatteLayer> out;
    for (const auto& [type, member] : {std::pair{"CryptoObject", &MatteNames::object}, std::pair{"CryptoMaterial", &MatteNames::material},
                                       std::pair{"CryptoAsset", &MatteNames::asset}}) {
        CryptomatteLayer layer;
        layer.name = type;
        std::vector<float> idOf(names.size());
        std::map<std::string, float> manifest;
        for (size_t h = 0; h < names.size(); ++h) {
            const std::string& name = names[h].*member;
            idOf[h] = cryptomatteId(murmurHash3(name));
            manifest.emplace(name, idOf[h]);
        }
        layer.ranks = rankCryptomatte(film, idOf);
        layer.manifest.assign(manifest.begin(), manifest.end());
        out.push_back(std::move(layer));
    }
    return out;
}

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

std::vector<std::string> renderPassChannels(const RenderPasses& passes)
{
    std::vector<std::string> names = renderPassChannels();
    for (const CryptomatteLayer& c : passes.cryptomatte)
        for (int layer = 0; layer < c.ranks.ranks / 2; ++layer)
            for (const char* ch : {".R", ".G", ".B", ".A"}) names.push_back(rankLayerName(c.name, layer) + ch);
    return names;
}

void writeRenderPasses(const std::string& path, const RenderPasses& passes)
{
    if (lowerExtension(path) != ".exr") throw Error(path + ": render passes are written as a multi-layer OpenEXR file (use .exr)");
    const size_t n = size_t(passes.width) * size_t(passes.height);
    for (const CryptomatteLayer& c : passes.cryptomatte)
        if (c.ranks.width != passes.width || c.ranks.height != passes.height)
            throw Error(path + ": the " + c.name + " matte is " + std::to_string(c.ranks.width) + "x" + std::to_string(c.ranks.height) +
                        ", the passes " + std::to_string(passes.width) + "x" + std::to_string(passes.height));
    const std::vector<std::string> names = renderPassChannels(passes);
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
        d += 2;
        for (const CryptomatteLayer& c : passes.cryptomatte) {   // the ranks' (ID, coverage) pairs in order: 4 per layer
            const size_t values = size_t(c.ranks.ranks) * 2;
            std::copy_n(&c.ranks.pairs[i * values], values, d);
            d += values;
        }
    }
    std::vector<std::string> header;
    for (const CryptomatteLayer& c : passes.cryptomatte) {
        const std::string key = "cryptomatte/" + cryptomatteKey(c.name) + "/";
        json::JsonWriter manifest;   // {"name":"hex8",...}
        manifest.raw("{");
        for (const auto& [name, id] : c.manifest) {
            if (manifest.text.size() > 1) manifest.raw(",");
            manifest.string(name);
            manifest.raw(":");
            manifest.string(cryptomatteHex(id));
        }
        manifest.raw("}");
        for (const std::string& s : {key + "name", c.name, key + "hash", std::string("MurmurHash3_32"), key + "conversion",
                                     std::string("uint32_to_float32"), key + "manifest", manifest.text})
            header.push_back(s);
    }
    writeImageChannels(path, passes.width, passes.height, names, data, header);
}

} // namespace sylva
