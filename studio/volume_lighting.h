// The volumes' LB lighting for the viewport: lit copies of the scene's volume data kept in memory across
// edits (as AssetStore keeps the species'), solved through the grid cache by lightSceneVolumes.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/scene/scene.h"

namespace sylva {

class Backend;
class GridCache;

// Thread-safe map from what a volume's lit data depends on (its loaded grid, the LB parameters with the
// scene's sun) to the lit data. The lighting jobs fill it; the viewport's scene reads it.
class VolumeLightStore {
public:
    // The key of volume `v` of `scene` (lit: with its LB lighting); empty for a volume that needs nothing
    // solved (unlit tracer or mode, no temperature grid): its loaded data serves as it is.
    static std::string key(const Scene& scene, const VolumeDesc& v, bool lit);
    // `scene` with each volume's data replaced by its lit copy. False (out untouched) when one is missing.
    bool litScene(const Scene& scene, bool lit, Scene* out) const;
    // Indices of the volumes whose lit data is missing.
    std::vector<size_t> missing(const Scene& scene, bool lit) const;
    // Solves the missing volumes' lighting (lightSceneVolumes: the grid cache answers a solve made before)
    // and keeps them. Throws Error or Cancelled.
    void ensure(const Scene& scene, bool lit, GridCache* cache, Progress* progress,
                const std::function<void(const std::string&)>& log, Backend* backend);
    void clear();
    size_t size() const;

private:
    struct Entry {
        std::shared_ptr<const VolumeData> source;   // keeps the key's grid address from being reused
        std::shared_ptr<const VolumeData> lit;
    };
    mutable std::mutex m_mutex;
    std::map<std::string, Entry> m_entries;
};

} // namespace sylva
