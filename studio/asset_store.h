// Species assets (mesh, textures, lighting grid) kept in memory across edits, keyed by what produced them.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"
#include "pipeline/lighting_job.h"

namespace sylva {

class Backend;
class GridCache;

using AssetsPtr = std::shared_ptr<const SpeciesAssets>;

// The key of a species' assets: its scene-file entry (name left out), and with lighting "|lit " and what its
// grid was solved for in the scene (speciesLightingKey: the LB sun, direct light, the sky in the boundary).
// Equal keys give equal assets.
std::string assetKey(const SpeciesDesc& species, const Scene& scene, bool lit);

// Thread-safe map key -> assets. Jobs fill it; the viewport and exports read it. The disk grid cache
// sits below it (a key missing here may still be a cache hit on disk).
class AssetStore {
public:
    AssetsPtr find(const std::string& key) const;
    void insert(const std::string& key, AssetsPtr assets);
    // Assets for every species of the scene (lit ones also serve unlit requests), or an empty vector
    // when any is missing.
    std::vector<AssetsPtr> forScene(const Scene& scene, bool lit) const;
    // Lit assets of every species for any sun (the first in key order: the same answer while the store
    // holds the same entries), or empty when a species has none: the geometry and grid layout a relit
    // frame keeps while the sun moves.
    std::vector<AssetsPtr> litForAnySun(const Scene& scene) const;
    // Keys of the scene's species that are missing.
    std::vector<size_t> missingSpecies(const Scene& scene, bool lit) const;
    // Drops every entry whose key is not in keep.
    void retainOnly(const std::vector<std::string>& keep);
    void clear();
    size_t size() const;

private:
    AssetsPtr findLocked(const SpeciesDesc& sp, const Scene& scene, bool lit) const;
    mutable std::mutex m_mutex;
    std::map<std::string, AssetsPtr> m_assets;
};

// Makes sure the store holds assets for every species of the scene (lit: with lighting grids):
// missing ones are loaded with loadSpeciesAssets (grow or import, then voxelize and light through the
// grid cache). Reports progress over the whole scene; log receives "SPECIES: STAGE" lines as they
// happen (from the calling thread). The LB solves run on backend (null = the CPU). Returns the scene's
// assets in species order. Throws Error or Cancelled.
std::vector<AssetsPtr> ensureAssets(const Scene& scene, bool lit, AssetStore& store, GridCache* cache,
                                    Progress* progress, const std::function<void(const std::string&)>& log,
                                    Backend* backend = nullptr);

} // namespace sylva
