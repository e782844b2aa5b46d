// The door to the OpenImageIO module: finds and loads libsylva_oiio.so once, on first use.
#include "pipeline/io/image_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "core/base/error.h"

#ifndef SYLVA_IMAGE_MODULE_BUILD_PATH
#define SYLVA_IMAGE_MODULE_BUILD_PATH ""
#endif
#ifndef SYLVA_IMAGE_MODULE_INSTALLED
#define SYLVA_IMAGE_MODULE_INSTALLED "../lib/sylva/libsylva_oiio.so"
#endif

namespace sylva::image_module {

namespace {

constexpr const char* kModuleName = "libsylva_oiio.so";

std::string executableFolder()
{
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string() : exe.parent_path().string();
}

// addSearchPath's places (guarded by the state's mutex, as candidates() is called under it).
std::vector<std::string>& extraPaths()
{
    static std::vector<std::string> paths;
    return paths;
}

// Where the module is looked for, in order.
std::vector<std::string> candidates()
{
    std::vector<std::string> out;
    if (const char* env = std::getenv("SYLVA_IMAGE_MODULE"); env && *env) return {env};
    const std::string folder = executableFolder();
    if (!folder.empty()) {
        out.push_back(folder + "/" + kModuleName);
        out.push_back(folder + "/" + SYLVA_IMAGE_MODULE_INSTALLED);
    }
    for (const std::string& p : extraPaths()) out.push_back(p);
    if (*SYLVA_IMAGE_MODULE_BUILD_PATH) out.push_back(SYLVA_IMAGE_MODULE_BUILD_PATH);
    return out;
}

struct State {
    std::mutex mutex;
    const Table* table = nullptr;
    std::string failure;   // the message of a load that failed (not retried)
};

State& state()
{
    static State s;
    return s;
}

// With the state's mutex held.
void loadLocked(State& s)
{
    if (s.table || !s.failure.empty()) return;
    std::string tried;
    for (const std::string& path : candidates()) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) {
            tried += "\n  " + path + ": no such file";
            continue;
        }
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char* e = dlerror();
            tried += "\n  " + path + ": " + (e ? e : "cannot load");
            continue;
        }
        using Entry = const Table* (*)();
        auto entry = reinterpret_cast<Entry>(dlsym(handle, "sylvaImageModule"));
        const Table* t = entry ? entry() : nullptr;
        if (!t || t->abi != kAbi) {
            tried += "\n  " + path + ": not this version's image module";
            dlclose(handle);
            continue;
        }
        s.table = t;   // never unloaded: OpenImageIO's libraries stay until the process ends
        return;
    }
    s.failure = "image files need the OpenImageIO module " + std::string(kModuleName) +
                " (set SYLVA_IMAGE_MODULE to its path); looked for it at:" + tried;
}

} // namespace

void addSearchPath(const std::string& path)
{
    State& s = state();
    std::lock_guard<std::mutex> lock(s.mutex);
    extraPaths().push_back(path);
}

const Table& table()
{
    State& s = state();
    std::lock_guard<std::mutex> lock(s.mutex);
    loadLocked(s);
    if (!s.table) throw Error(s.failure);
    return *s.table;
}

void requireFindable()
{
    State& s = state();
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.table) return;
    if (s.failure.empty()) {
        bool any = false;
        for (const std::string& path : candidates()) {
            std::error_code ec;
            any = any || std::filesystem::exists(path, ec);
        }
        if (!any) loadLocked(s);   // records the places it looked
    }
    if (!s.failure.empty()) throw Error(s.failure);
}

std::unique_ptr<Reader> Reader::open(const std::string& path, bool unassociatedAlpha, std::string& error)
{
    const Table& t = table();
    std::unique_ptr<Reader> r(new Reader);
    r->m_table = &t;
    r->m_input = t.openRead(path.c_str(), unassociatedAlpha ? 1 : 0, &r->m_info, &error);
    if (!r->m_input) return nullptr;
    return r;
}

Reader::~Reader()
{
    if (m_input) m_table->closeRead(m_input);
}

bool Reader::read(int channels, std::vector<float>& out, std::string& error)
{
    out.assign(size_t(m_info.width) * size_t(m_info.height) * size_t(channels), 0.0f);
    return m_table->readFloat(m_input, channels, out.data(), &error) != 0;
}

std::unique_ptr<Writer> Writer::open(const std::string& path, int width, int height, int channels, const std::vector<std::string>* names,
                                     SampleType stored, int alphaChannel, ColorSpace colorSpace, std::string& error,
                                     const std::vector<std::string>* attributes)
{
    const Table& t = table();
    if (names && int(names->size()) != channels) {
        error = "channel names do not match the channel count";
        return nullptr;
    }
    if (attributes && attributes->size() % 2 != 0) {
        error = "header attributes come as name, value pairs";
        return nullptr;
    }
    std::unique_ptr<Writer> w(new Writer);
    w->m_table = &t;
    w->m_output = t.openWrite(path.c_str(), width, height, channels, names ? names->data() : nullptr, stored, alphaChannel, colorSpace,
                               attributes && !attributes->empty() ? attributes->data() : nullptr, attributes ? int(attributes->size() / 2) : 0, &error);
    if (!w->m_output) return nullptr;
    return w;
}

Writer::~Writer()
{
    std::string ignored;
    if (m_output) m_table->closeWrite(m_output, &ignored);
}

bool Writer::writeImage(const float* data, std::string& error) { return m_table->writeImage(m_output, data, &error) != 0; }

bool Writer::writeRows(int y0, int y1, const float* data, std::string& error) { return m_table->writeRows(m_output, y0, y1, data, &error) != 0; }

bool Writer::close(std::string& error)
{
    void* o = m_output;
    m_output = nullptr;
    return m_table->closeWrite(o, &error) != 0;
}

} // namespace sylva::image_module
