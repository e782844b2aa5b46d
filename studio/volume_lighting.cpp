// VolumeLightStore: lit volume data per (grid, LB parameters), through lightSceneVolumes.
#include "studio/volume_lighting.h"

#include <cstdio>

#include "core/base/error.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/volume_job.h"

namespace sylva {

std::string VolumeLightStore::key(const Scene& scene, const VolumeDesc& v, bool lit)
{
    if (!v.data) return {};
    const bool solve = lit && v.lit;
    if (!solve && v.data->temperature.empty()) return {};
    char buf[48];
    std::snprintf(buf, sizeof buf, "%p|", static_cast<const void*>(v.data.get()));
    std::string k = buf;
    if (solve) k += lightingParamsJson(volumeLightingParams(scene, v), v.preset, v.data->density.geometry.dims);
    else k += "unlit";
    return k;
}

bool VolumeLightStore::litScene(const Scene& scene, bool lit, Scene* out) const
{
    std::vector<std::shared_ptr<const VolumeData>> data(scene.volumes.size());
    {
        std::lock_guard lock(m_mutex);
        for (size_t i = 0; i < scene.volumes.size(); ++i) {
            const VolumeDesc& v = scene.volumes[i];
            const std::string k = key(scene, v, lit);
            if (k.empty()) {
                data[i] = v.data;
                continue;
            }
            auto it = m_entries.find(k);
            if (it == m_entries.end()) return false;
            data[i] = it->second.lit;
        }
    }
    *out = scene;
    for (size_t i = 0; i < data.size(); ++i) out->volumes[i].data = data[i];
    return true;
}

std::vector<size_t> VolumeLightStore::missing(const Scene& scene, bool lit) const
{
    std::lock_guard lock(m_mutex);
    std::vector<size_t> out;
    for (size_t i = 0; i < scene.volumes.size(); ++i) {
        const std::string k = key(scene, scene.volumes[i], lit);
        if (!k.empty() && m_entries.find(k) == m_entries.end()) out.push_back(i);
    }
    return out;
}

void VolumeLightStore::ensure(const Scene& scene, bool lit, GridCache* cache, Progress* progress,
                              const std::function<void(const std::string&)>& log, Backend* backend)
{
    const std::vector<size_t> todo = missing(scene, lit);
    for (size_t m = 0; m < todo.size(); ++m) {
        const VolumeDesc& v = scene.volumes[todo[m]];
        SubProgress part(progress, double(m) / double(todo.size()), double(m + 1) / double(todo.size()));
        Progress sub([&](double f, const std::string& msg) { part.report(f, msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        Scene one = scene;   // the scene's sun, one volume
        one.volumes.assign(1, v);
        JobLog jobLog;
        Scene done;
        try {
            done = lightSceneVolumes(one, cache, lit, &sub, &jobLog, backend);
        } catch (...) {
            if (progress && progress->isCancelled()) throw Cancelled();
            throw;
        }
        if (log) {
            for (const std::string& st : jobLog.stages) log(st);
            for (const std::string& w : jobLog.warnings) log("warning: " + w);
        }
        std::lock_guard lock(m_mutex);
        m_entries[key(scene, v, lit)] = Entry{v.data, done.volumes.at(0).data};
    }
}

void VolumeLightStore::clear()
{
    std::lock_guard lock(m_mutex);
    m_entries.clear();
}

size_t VolumeLightStore::size() const
{
    std::lock_guard lock(m_mutex);
    return m_entries.size();
}

} // namespace sylva
