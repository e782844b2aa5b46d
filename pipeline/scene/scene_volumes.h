// The scene file's volumes (docs/SCENE.md "volumes"): their field table and the loading of their grids.
#pragma once

#include "pipeline/scene/scene_fields.h"

namespace sylva {

// A volume entry's defaults when read (preset cloud, the LB's 2 steps per edge, fp16 lighting storage).
VolumeDesc defaultVolume();

// The fields of one entry of "volumes".
const json::Table<VolumeDesc>& volumeTable();

// One line per volume for `sylva info`; empty without volumes.
std::string describeVolumes(const Scene& scene);

// Reads every volume's density (and temperature) grid into VolumeDesc::data: density x density_scale
// must be finite and in [0, 1] (the LB's range), temperatures finite and >= 0, grids at least 2 nodes
// a side and of equal dims. Throws Error naming the volume and the file. The LB lighting is solved
// later (pipeline/render: lightSceneVolumes).
void loadSceneVolumes(Scene& scene);

} // namespace sylva
