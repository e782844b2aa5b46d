// GPU frame: the same shadePixel as the CPU loop, one thread per pixel, 8x8-pixel blocks (seed 000 section 4.3).
#include "cuda/render_cuda.h"

#include <vector>

#include "core/render/shade.h"
#include "core/render/tonemap.h"
#include "cuda/cuda_check.h"

namespace sylva::cuda {
namespace {

constexpr int kTile = 8;
// Traversal is latency-bound: more warps in flight beat registers. At 64 registers per thread (16
// blocks of 64 threads per SM) the default forest frame ran 1.27x faster on an H100 than at the 168 the
// compiler picks alone (96: 1.12x, 128: 1.07x; docs/PERFORMANCE.md "GPU").
constexpr int kMinBlocksPerSm = 16;

template <bool AnyHit>
__global__ void __launch_bounds__(128, kMinBlocksPerSm / 2) raysKernel(RenderView v, const Ray* rays, size_t n, Hit* hits)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    Hit h{};
    const bool got = traceScene<AnyHit>(v, rays[i], h);
    if (AnyHit) h.prim = got ? 0u : kNoHit;
    hits[i] = h;
}

__global__ void __launch_bounds__(kTile * kTile, kMinBlocksPerSm) shadeKernel(RenderView v, SampleParts* film)
{
    const int x = int(blockIdx.x) * kTile + int(threadIdx.x), y = int(blockIdx.y) * kTile + int(threadIdx.y);
    if (x >= v.width || y >= v.height) return;
    film[size_t(y) * size_t(v.width) + size_t(x)] = shadePixel(v, x, y);
}

// Block-wide sum of one double per thread, added to *out by one atomic per block (blockDim.x == 256).
__device__ void blockSum(double v, double* out)
{
    __shared__ double warpSums[8];
    for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
    const int lane = int(threadIdx.x) & 31, warp = int(threadIdx.x) >> 5;
    if (lane == 0) warpSums[warp] = v;
    __syncthreads();
    if (warp == 0) {
        v = lane < 8 ? warpSums[lane] : 0.0;
        for (int o = 4; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
        if (lane == 0) atomicAdd(out, v);
    }
}

// The sums the tone mapper needs, with the host's per-pixel rules (core/render/tonemap.h): acc[1] = sum
// lum(indirect), acc[2] = sum lum(albedo) (the ambient constant of the ambient mode); acc[0] and acc[3] the
// log-luminance terms of the left and right modes, acc[4] and acc[5] the pixels they counted (non-finite
// ones are left out, as on the host).
constexpr int kToneSums = 6;

__global__ void ambientSums(const SampleParts* film, size_t n, double* acc)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    const bool in = i < n;
    blockSum(in ? double(luminance(film[i].indirect)) : 0.0, &acc[1]);
    blockSum(in ? double(luminance(film[i].albedo)) : 0.0, &acc[2]);
}

__device__ float ambientOf(const double* acc) { return ambientConstant(acc[1], acc[2]); }

__global__ void logSum(const SampleParts* film, size_t n, RenderMode mode, glm::vec3 sky, double* acc, double* sum, double* count)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    double term = 0.0;
    const bool counted = i < n && logLuminanceTerm(composeSample(film[i], mode, sky, ambientOf(acc)), term);
    blockSum(counted ? term : 0.0, sum);
    blockSum(counted ? 1.0 : 0.0, count);
}

__global__ void toneMapKernel(const SampleParts* film, int width, size_t n, RenderMode left, RenderMode right, glm::vec3 sky,
                              float key, const double* acc, uint32_t* out)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const bool isRight = int(i % size_t(width)) >= width / 2 && right != left;
    const float scale = exposureScale(key, logAverageOf(acc[isRight ? 3 : 0], acc[isRight ? 5 : 4]));
    const glm::vec3 c = reinhard(composeSample(film[i], isRight ? right : left, sky, ambientOf(acc)), scale);
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

namespace {

// Device memory that keeps its allocation while what it holds shrinks or grows a little.
struct Reusable {
    DeviceBuffer<char> buffer;
    size_t capacity = 0;
    template <typename T>
    const T* assign(const std::vector<T>& host, const char* what)
    {
        const size_t bytes = host.size() * sizeof(T);
        if (bytes > capacity) {
            buffer.allocate(bytes + bytes / 4, what);
            capacity = bytes + bytes / 4;
        }
        if (bytes) check(cudaMemcpy(buffer.get(), host.data(), bytes, cudaMemcpyHostToDevice), what);
        return bytes ? reinterpret_cast<const T*>(buffer.get()) : nullptr;
    }
};

} // namespace

struct DeviceScene::Scratch {
    DeviceBuffer<SampleParts> film;
    DeviceBuffer<double> acc{kToneSums, "tone map sums"};
    SampleParts* filmFor(size_t n)
    {
        if (film.size() < n) film.allocate(n, "film");
        return film.get();
    }
};

struct DeviceScene::Buffers {
    std::vector<DeviceBuffer<char>> owned;      // the scene part
    // The top level, re-placed per camera: a reusable buffer per array (only the Top ones are used).
#define SYLVA_X(part, where, T, name, stat) Reusable name;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    Scratch scratch;
};

namespace {

// Whether an array goes to the device (host-only ones stay null there).
template <ArrayPart P, ArrayWhere W>
inline constexpr bool kUploaded = W == ArrayWhere::Both;

} // namespace

// The scene part goes up once; the host-only arrays stay null on the device; place() sends the top level.
DeviceScene::DeviceScene(const RenderScene& s) : m_buffers(std::make_unique<Buffers>())
{
    auto& o = m_buffers->owned;
    size_t& b = m_speciesBytes;
#define SYLVA_X(part, where, T, name, stat)                                                                        \
    if constexpr (ArrayPart::part == ArrayPart::Scene && kUploaded<ArrayPart::part, ArrayWhere::where>) \
        m_scene.name = put(o, b, s.name);
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    m_speciesCount = s.species.size();
    m_geometryCount = s.geometries.size();
    place(s);
}

void DeviceScene::place(const RenderScene& s)
{
    if (s.species.size() != m_speciesCount || s.geometries.size() != m_geometryCount)
        throw BackendError("CUDA: the scene's species differ from the uploaded ones");
    Buffers& bufs = *m_buffers;
    RenderView v = s.view();   // settings and environment; host pointers replaced below
    size_t topBytes = 0;
#define SYLVA_X(part, where, T, name, stat)                                                          \
    if constexpr (!kUploaded<ArrayPart::part, ArrayWhere::where>) {                                     \
        v.name = nullptr;                                                                              \
    } else if constexpr (ArrayPart::part == ArrayPart::Scene) {                                         \
        v.name = m_scene.name;                                                                         \
    } else {                                                                                           \
        v.name = bufs.name.assign(s.name, "top level upload (" #name ")");                              \
        topBytes += bufs.name.capacity;                                                                \
    }
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    m_view = v;
    m_bytes = m_speciesBytes + topBytes;
}

DeviceScene::Scratch& DeviceScene::scratch() const { return m_buffers->scratch; }

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

void renderToRgba8(const DeviceScene& scene, RenderMode mode, float key, uint32_t* deviceRgba8, std::optional<RenderMode> right)
{
    const RenderView& v = scene.view();
    const size_t n = size_t(v.width) * size_t(v.height);
    DeviceScene::Scratch& s = scene.scratch();
    SampleParts* film = s.filmFor(n);
    traceOnDevice(v, film);
    double* acc = s.acc.get();
    check(cudaMemset(acc, 0, kToneSums * sizeof(double)), "tone map sums");
    const unsigned blocks = unsigned((n + 255) / 256);
    const RenderMode r = right.value_or(mode);
    if (mode == RenderMode::Ambient || r == RenderMode::Ambient) ambientSums<<<blocks, 256>>>(film, n, acc);
    logSum<<<blocks, 256>>>(film, n, mode, v.sky, acc, &acc[0], &acc[4]);
    if (r != mode) logSum<<<blocks, 256>>>(film, n, r, v.sky, acc, &acc[3], &acc[5]);
    toneMapKernel<<<blocks, 256>>>(film, v.width, n, mode, r, v.sky, key, acc, deviceRgba8);
    check(cudaGetLastError(), "tone map kernels");
    check(cudaDeviceSynchronize(), "tone map");
}

} // namespace sylva::cuda
