// GPU frame: the same shadePixel as the CPU loop, one thread per pixel, 8x8-pixel blocks (seed 000 section 4.3).
#include "cuda/render_cuda.h"

#include <vector>

#include "core/render/shade.h"
#include "core/render/tonemap.h"
#include "cuda/cuda_check.h"

namespace sylva::cuda {
namespace {

constexpr int kTile = 8;

template <bool AnyHit>
__global__ void raysKernel(RenderView v, const Ray* rays, size_t n, Hit* hits)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    Hit h{};
    const bool got = traceScene<AnyHit>(v, rays[i], h);
    if (AnyHit) h.prim = got ? 0u : kNoHit;
    hits[i] = h;
}

__global__ void shadeKernel(RenderView v, SampleParts* film)
{
    const int x = int(blockIdx.x) * kTile + int(threadIdx.x), y = int(blockIdx.y) * kTile + int(threadIdx.y);
    if (x >= v.width || y >= v.height) return;
    film[size_t(y) * size_t(v.width) + size_t(x)] = shadePixel(v, x, y);
}

// The sums the tone mapper needs: acc[0] = sum log(1e-4 + L), acc[1] = sum lum(indirect), acc[2] =
// sum lum(albedo) (the ambient constant of the ambient mode).
__global__ void ambientSums(const SampleParts* film, size_t n, double* acc)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    atomicAdd(&acc[1], double(luminance(film[i].indirect)));
    atomicAdd(&acc[2], double(luminance(film[i].albedo)));
}

__global__ void logSum(const SampleParts* film, size_t n, RenderMode mode, glm::vec3 sky, const double* ambientAcc, double* acc)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const float ambient = ambientAcc[2] > 0.0 ? float(ambientAcc[1] / ambientAcc[2]) : 0.0f;
    const float l = luminance(composeSample(film[i], mode, sky, ambient));
    atomicAdd(&acc[0], double(logf(1e-4f + fmaxf(l, 0.0f))));
}

__global__ void toneMapKernel(const SampleParts* film, size_t n, RenderMode mode, glm::vec3 sky, float key, const double* acc,
                              uint32_t* out)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const float ambient = acc[2] > 0.0 ? float(acc[1] / acc[2]) : 0.0f;
    const float logAvg = expf(float(acc[0] / double(n)));
    const glm::vec3 c = reinhard(composeSample(film[i], mode, sky, ambient), key / logAvg);
    const uint32_t r = uint32_t(srgbEncode(c.x) * 255.0f + 0.5f), g = uint32_t(srgbEncode(c.y) * 255.0f + 0.5f),
                   b = uint32_t(srgbEncode(c.z) * 255.0f + 0.5f);
    out[i] = r | (g << 8) | (b << 16) | (255u << 24);
}

template <typename T>
const T* put(std::vector<DeviceBuffer<char>>& owned, size_t& bytes, const std::vector<T>& host)
{
    DeviceBuffer<char> b;
    b.upload(reinterpret_cast<const char*>(host.data()), host.size() * sizeof(T), "scene upload");
    bytes += host.size() * sizeof(T);
    owned.push_back(std::move(b));
    return reinterpret_cast<const T*>(owned.back().get());
}

} // namespace

struct DeviceScene::Buffers {
    std::vector<DeviceBuffer<char>> owned;
};

DeviceScene::DeviceScene(const RenderScene& s) : m_buffers(std::make_unique<Buffers>())
{
    auto& o = m_buffers->owned;
    m_view = s.view();
    m_view.tlasNodes = put(o, m_bytes, s.tlasNodes);
    m_view.tlasOrder = put(o, m_bytes, s.tlasOrder);
    m_view.instances = put(o, m_bytes, s.instances);
    m_view.species = put(o, m_bytes, s.species);
    m_view.blasNodes = put(o, m_bytes, s.blasNodes);
    m_view.tris = put(o, m_bytes, s.tris);
    m_view.blocks = put(o, m_bytes, s.blocks);
    m_view.kdTlasNodes = s.kdTlasNodes.empty() ? nullptr : put(o, m_bytes, s.kdTlasNodes);
    m_view.kdTlasRefs = put(o, m_bytes, s.kdTlasRefs);
    m_view.kdSpecies = put(o, m_bytes, s.kdSpecies);
    m_view.kdBlasNodes = put(o, m_bytes, s.kdBlasNodes);
    m_view.kdBlasRefs = put(o, m_bytes, s.kdBlasRefs);
    m_view.triVerts = put(o, m_bytes, s.triVerts);
    m_view.triMaterial = put(o, m_bytes, s.triMaterial);
    m_view.normals = put(o, m_bytes, s.normals);
    m_view.uvs = put(o, m_bytes, s.uvs);
    m_view.materials = put(o, m_bytes, s.materials);
    m_view.textures = put(o, m_bytes, s.textures);
    m_view.texels = put(o, m_bytes, s.texels);
    m_view.alphaMasks = put(o, m_bytes, s.alphaMasks);
    m_view.alphaBits = put(o, m_bytes, s.alphaBits);
    m_view.lighting = put(o, m_bytes, s.lighting);
}

DeviceScene::~DeviceScene() = default;

namespace {

void traceOnDevice(const RenderView& v, SampleParts* film)
{
    const dim3 block(kTile, kTile);
    const dim3 grid(unsigned((v.width + kTile - 1) / kTile), unsigned((v.height + kTile - 1) / kTile));
    shadeKernel<<<grid, block>>>(v, film);
    check(cudaGetLastError(), "shading kernel launch");
    check(cudaDeviceSynchronize(), "shading kernel");
}

} // namespace

Film renderCuda(const DeviceScene& scene, Progress* progress)
{
    const RenderView& v = scene.view();
    Film film;
    film.width = v.width;
    film.height = v.height;
    film.pixels.resize(size_t(v.width) * size_t(v.height));
    DeviceBuffer<SampleParts> d(film.pixels.size(), "film");
    if (progress) progress->report(0.0, "tracing on the GPU");
    traceOnDevice(v, d.get());
    d.download(film.pixels.data(), film.pixels.size(), "film");
    if (progress) progress->report(1.0, "tracing on the GPU");
    return film;
}

std::vector<Hit> traceRaysCuda(const DeviceScene& scene, const std::vector<Ray>& rays, bool anyHit)
{
    DeviceBuffer<Ray> d;
    d.upload(rays.data(), rays.size(), "rays");
    DeviceBuffer<Hit> h(rays.size(), "hits");
    const unsigned blocks = unsigned((rays.size() + 127) / 128);
    if (anyHit) raysKernel<true><<<blocks, 128>>>(scene.view(), d.get(), rays.size(), h.get());
    else raysKernel<false><<<blocks, 128>>>(scene.view(), d.get(), rays.size(), h.get());
    check(cudaGetLastError(), "ray kernel launch");
    check(cudaDeviceSynchronize(), "ray kernel");
    std::vector<Hit> out(rays.size());
    h.download(out.data(), out.size(), "hits");
    return out;
}

void renderToRgba8(const DeviceScene& scene, RenderMode mode, float key, uint32_t* deviceRgba8)
{
    const RenderView& v = scene.view();
    const size_t n = size_t(v.width) * size_t(v.height);
    DeviceBuffer<SampleParts> film(n, "film");
    traceOnDevice(v, film.get());
    DeviceBuffer<double> acc(3, "tone map sums");
    check(cudaMemset(acc.get(), 0, 3 * sizeof(double)), "tone map sums");
    const unsigned blocks = unsigned((n + 255) / 256);
    if (mode == RenderMode::Ambient) ambientSums<<<blocks, 256>>>(film.get(), n, acc.get());
    logSum<<<blocks, 256>>>(film.get(), n, mode, v.sky, acc.get(), acc.get());
    toneMapKernel<<<blocks, 256>>>(film.get(), n, mode, v.sky, key, acc.get(), deviceRgba8);
    check(cudaGetLastError(), "tone map kernels");
    check(cudaDeviceSynchronize(), "tone map");
}

} // namespace sylva::cuda
