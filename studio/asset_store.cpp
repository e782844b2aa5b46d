// AssetStore and ensureAssets: per-species loading through loadSpeciesAssets, in memory across edits.
#include "studio/asset_store.h"

#include <algorithm>

#include "pipeline/render/render_job.h"
#include "pipeline/services/exports.h"
#include "studio/scene_document.h"

namespace sylva {

std::string assetKey(const SpeciesDesc& species, const Scene& scene, bool lit)
{
    std::string key = speciesFingerprint(species);
    if (lit) key += "|lit " + speciesLightingKey(scene);
    return key;
}

AssetsPtr AssetStore::find(const std::string& key) const
{
    std::lock_guard lock(m_mutex);
    auto it = m_assets.find(key);
    return it == m_assets.end() ? nullptr : it->second;
}

void AssetStore::insert(const std::string& key, AssetsPtr assets)
{
    std::lock_guard lock(m_mutex);
    m_assets[key] = std::move(assets);
}

AssetsPtr AssetStore::findLocked(const SpeciesDesc& sp, const Scene& scene, bool lit) const
{
    auto it = m_assets.find(assetKey(sp, scene, true));
    if (it != m_assets.end()) return it->second;
    if (lit) return nullptr;
    it = m_assets.find(assetKey(sp, scene, false));
    return it == m_assets.end() ? nullptr : it->second;
}

std::vector<AssetsPtr> AssetStore::forScene(const Scene& scene, bool lit) const
{
    std::lock_guard lock(m_mutex);
    std::vector<AssetsPtr> out;
    for (const SpeciesDesc& sp : scene.species) {
        AssetsPtr a = findLocked(sp, scene, lit);
        if (!a) return {};
        out.push_back(std::move(a));
    }
    return out;
}

std::vector<AssetsPtr> AssetStore::litForAnySun(const Scene& scene) const
{
    std::lock_guard lock(m_mutex);
    std::vector<AssetsPtr> out;
    for (const SpeciesDesc& sp : scene.species) {
        const std::string prefix = assetKey(sp, scene, false) + "|lit sun ";
        auto it = m_assets.lower_bound(prefix);
        if (it != m_assets.end() && it->first.compare(0, prefix.size(), prefix) != 0) it = m_assets.end();
        if (it == m_assets.end()) return {};
        out.push_back(it->second);
    }
    return out;
}

std::vector<size_t> AssetStore::missingSpecies(const Scene& scene, bool lit) const
{
    std::lock_guard lock(m_mutex);
    std::vector<size_t> out;
    for (size_t s = 0; s < scene.species.size(); ++s)
        if (!findLocked(scene.species[s], scene, lit)) out.push_back(s);
    return out;
}

void AssetStore::retainOnly(const std::vector<std::string>& keep)
{
    std::lock_guard lock(m_mutex);
    for (auto it = m_assets.begin(); it != m_assets.end();) {
        if (std::find(keep.begin(), keep.end(), it->first) == keep.end()) it = m_assets.erase(it);
        else ++it;
    }
}

void AssetStore::clear()
{
    std::lock_guard lock(m_mutex);
    m_assets.clear();
}

size_t AssetStore::size() const
{
    std::lock_guard lock(m_mutex);
    return m_assets.size();
}

std::vector<AssetsPtr> ensureAssets(const Scene& scene, bool lit, AssetStore& store, GridCache* cache,
                                    Progress* progress, const std::function<void(const std::string&)>& log,
                                    Backend* backend)
{
    const std::vector<size_t> missing = store.missingSpecies(scene, lit);
    for (size_t m = 0; m < missing.size(); ++m) {
        const SpeciesDesc& sp = scene.species[missing[m]];
        SubProgress part(progress, double(m) / double(missing.size()), double(m + 1) / double(missing.size()));
        Progress sub([&](double f, const std::string& msg) { part.report(f, msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        // One species at a time (a scene of one species), so each lands in the store as it is done.
        Scene one;
        one.species.push_back(sp);
        one.sun = scene.sun;
        one.sky = scene.sky;
        one.skyModel = scene.skyModel;
        one.lighting = scene.lighting;
        JobLog jobLog;
        std::vector<SpeciesAssets> loaded;
        try {
            loaded = loadSpeciesAssets(one, cache, lit, &sub, &jobLog, backend);
        } catch (...) {
            if (progress && progress->isCancelled()) throw Cancelled();
            throw;
        }
        if (log)
            for (const std::string& line : speciesLogLines(sp.name, jobLog)) log(line);
        store.insert(assetKey(sp, scene, lit), std::make_shared<const SpeciesAssets>(std::move(loaded.at(0))));
        if (progress) progress->report(double(m + 1) / double(missing.size()), sp.name + ": done");
    }
    std::vector<AssetsPtr> out = store.forScene(scene, lit);
    if (out.size() != scene.species.size()) throw Error("assets: a species went missing while loading");
    return out;
}

} // namespace sylva
