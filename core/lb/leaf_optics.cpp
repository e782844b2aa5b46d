// Leaf optics of an LB channel and the renderer's weights for scattered light (leaf_optics.h).
#include "core/lb/leaf_optics.h"

#include <cmath>

namespace sylva::lb {

double forwardShare(double g)
{
    if (std::fabs(g) < 1e-6) return 0.5 + 0.375 * g;   // series: 1/2 + 3g/8 + O(g^3)
    if (g >= 1.0) return 1.0;
    if (g <= -1.0) return 0.0;
    return (1.0 + g) / (2.0 * g) - (1.0 - g * g) / (2.0 * g * std::sqrt(1.0 + g * g));
}

LeafOptics leafOptics(const LbParams& params)
{
    LeafOptics o{};
    for (int c = 0; c < 3; ++c) {
        const ChannelParams& ch = params.channels[size_t(c)];
        const double st = double(ch.sigmaA) + double(ch.sigmaS);
        const double a = st > 0.0 ? double(ch.sigmaS) / st : 0.0;
        const double f = forwardShare(double(ch.g));
        o.albedo[c] = float(a);
        o.transmittance[c] = float(a * f);
        o.reflectance[c] = float(a * (1.0 - f));
        o.ratio[c] = f < 1.0 ? float(f / (1.0 - f)) : 0.0f;
    }
    return o;
}

ScatteredWeights scatteredWeights(const LbParams& params)
{
    const LeafOptics o = leafOptics(params);
    return {(glm::vec3(1.0f) + o.ratio) * 0.25f, 0.25f, kMaxLeafScattering * 0.25f};
}

} // namespace sylva::lb
