// GPU frame: the same shadePixel as the CPU loop, one thread per pixel, 8x8-pixel blocks (Geist & Steele, "A
// Lighting Model for Fast Rendering of Forest Ecosystems", section 4.3).
#include "cuda/render_cuda.h"

#include <vector>

#include "core/render/shade.h"
#include "core/render/tonemap_film.h"
#include "cuda/cuda_check.h"
#include "cuda/device_exec.cuh"

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
    toneMapFilm(CudaExec{}, film, v.width, v.height, mode, right.value_or(mode), v.sky.constant, key, s.acc.get(), deviceRgba8);
    check(cudaDeviceSynchronize(), "tone map");
}

} // namespace sylva::cuda
