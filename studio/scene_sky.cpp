// refreshSceneSky: loadSceneSky when a sky edit needs it, with the maps kept in memory by path.
#include "studio/scene_sky.h"

#include <filesystem>
#include <list>
#include <mutex>
#include <utility>

#include "core/base/error.h"
#include "pipeline/io/env_map_io.h"

namespace sylva {
namespace {

// The last few maps read (path and modification time): a rotation or intensity drag builds the sky
// from memory. A map is a few to a few tens of MB.
class MapMemory {
public:
    EnvMapFile read(const std::string& path)
    {
        std::error_code ec;
        const auto stamp = std::filesystem::last_write_time(path, ec);
        std::lock_guard lock(m_mutex);
        for (auto it = m_maps.begin(); it != m_maps.end(); ++it)
            if (it->path == path && !ec && it->stamp == stamp) {
                m_maps.splice(m_maps.begin(), m_maps, it);
                return it->file;
            }
        EnvMapFile f = readEnvMap(path);
        if (!ec) {
            m_maps.push_front({path, stamp, f});
            if (m_maps.size() > kKeep) m_maps.pop_back();
        }
        return f;
    }

private:
    static constexpr size_t kKeep = 4;
    struct Entry {
        std::string path;
        std::filesystem::file_time_type stamp;
        EnvMapFile file;
    };
    std::mutex m_mutex;
    std::list<Entry> m_maps;
};

MapMemory& maps()
{
    static MapMemory m;
    return m;
}

} // namespace

bool sameSkySettings(const SkyDesc& a, const SkyDesc& b)
{
    return a.kind == b.kind && a.turbidity == b.turbidity && a.scale == b.scale && a.path == b.path && a.rotationDeg == b.rotationDeg &&
           a.intensity == b.intensity && a.lights == b.lights && a.interleave == b.interleave && a.sunFromMap == b.sunFromMap &&
           a.aerialPerspective == b.aerialPerspective && a.built == b.built;
}

bool sameSunPlace(const SunDesc& a, const SunDesc& b)
{
    if (a.place.has_value() != b.place.has_value()) return false;
    if (!a.place) return true;
    const sky::SunPlace &p = *a.place, &q = *b.place;
    return p.year == q.year && p.month == q.month && p.day == q.day && p.hour == q.hour && p.timeZoneHours == q.timeZoneHours &&
           p.latitudeDeg == q.latitudeDeg && p.longitudeDeg == q.longitudeDeg && p.refraction == q.refraction;
}

bool refreshSceneSky(const Scene& before, Scene& after, std::string* error)
{
    SkyDesc& d = after.skyModel;
    if (!d.analytic()) {
        d.built.reset();
        return true;
    }
    const SkyDesc& o = before.skyModel;
    bool same = d.built && d.built == o.built && d.kind == o.kind;
    if (d.kind == sky::SkyKind::Preetham)
        same = same && d.turbidity == o.turbidity && d.scale == o.scale && after.sun.direction == before.sun.direction;
    else if (d.kind == sky::SkyKind::Uniform)
        same = same && after.sky == before.sky;
    else
        same = same && d.path == o.path && d.rotationDeg == o.rotationDeg && d.intensity == o.intensity && d.sunFromMap == o.sunFromMap;
    if (same) return true;
    Scene trial = after;
    trial.skyModel.built.reset();
    try {
        loadSceneSky(trial, [](const std::string& path) { return maps().read(path); });
    } catch (const Error& e) {
        if (error) *error = e.what();
        return false;
    }
    d.built = trial.skyModel.built;
    return true;
}

} // namespace sylva
