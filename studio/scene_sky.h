// The scene's built sky (SkyDesc::built) kept in step with its settings as the studio edits them: a
// Preetham sky follows its turbidity, scale and the sun; a map sky its file, rotation, intensity and sun
// option (the files read once and kept in memory); the constant sky holds none.
#pragma once

#include <string>

#include "core/scene/scene.h"

namespace sylva {

// Whether two scenes' sky settings differ (kind and the keys of the sky block beyond the colour) or the
// sun's date and place do: what changedParts adds to ScenePart::Sky / ScenePart::Sun.
bool sameSkySettings(const SkyDesc& a, const SkyDesc& b);
bool sameSunPlace(const SunDesc& a, const SunDesc& b);

// Builds after.skyModel.built again when `after` needs another sky than `before` holds (its settings or,
// for a Preetham sky, the sun's direction changed, or it has none), else keeps it. false (after unchanged
// where it matters, *error the reason): the map cannot be read or the model refuses the sun.
bool refreshSceneSky(const Scene& before, Scene& after, std::string* error);

} // namespace sylva
