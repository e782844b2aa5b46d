// The atmosphere kind's record from the scene's sky (atmosphere.h).
#include "core/render/surfaces/atmosphere.h"

#include <cmath>
#include <string>

#include "core/base/error.h"
#include "core/sky/preetham.h"

namespace sylva {

AtmosphereRecord makeAtmosphere(double turbidity, double cameraY)
{
    if (!std::isfinite(turbidity) || turbidity < sky::kMinTurbidity || turbidity > sky::kMaxTurbidity)
        throw Error("aerial perspective: turbidity must be in 2 .. 10, got " + std::to_string(turbidity));
    if (!std::isfinite(cameraY)) throw Error("aerial perspective: the camera's height is not finite");
    AtmosphereRecord a{};
    a.enabled = 1;
    a.cameraY = float(cameraY);
    for (int c = 0; c < 3; ++c) {
        const double lambda = kAtmosphereWavelengthsNm[c];
        a.rayleigh[c] = float(sky::rayleighOpticalDepth(lambda) / double(kRayleighScaleHeight));
        a.aerosol[c] = float(sky::aerosolOpticalDepth(lambda, turbidity) / double(kAerosolScaleHeight));
    }
    return a;
}

} // namespace sylva
