// The monotonic tricubic interpolation of the smoke simulation (smoke_interp.h).
#include "core/volume/smoke_interp.h"

#include <algorithm>
#include <cmath>

namespace sylva::volume::smoke_detail {

float monotonicCubic(float f0, float f1, float f2, float f3, float t)
{
    const float delta = f2 - f1;
    float d1 = 0.5f * (f2 - f0), d2 = 0.5f * (f3 - f1);
    if (delta == 0.0f) {
        d1 = d2 = 0.0f;
    } else {
        if ((d1 > 0.0f) != (delta > 0.0f) || d1 == 0.0f) d1 = 0.0f;
        if ((d2 > 0.0f) != (delta > 0.0f) || d2 == 0.0f) d2 = 0.0f;
        // Fritsch-Carlson: slopes at most 3 times the secant keep the Hermite piece monotone.
        const float cap = 3.0f * std::fabs(delta);
        d1 = std::clamp(d1, -cap, cap);
        d2 = std::clamp(d2, -cap, cap);
    }
    const float a3 = d1 + d2 - 2.0f * delta, a2 = 3.0f * delta - 2.0f * d1 - d2;
    return ((a3 * t + a2) * t + d1) * t + f1;
}

float sampleCubic(const FieldView& f, const glm::vec3& pos)
{
    int i0[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        const float s = std::clamp(pos[a] - f.offset[a], 0.0f, float(f.n[a] - 1));
        i0[a] = std::min(int(s), f.n[a] - 2);
        t[a] = s - float(i0[a]);
    }
    auto ci = [&](int a, int d) { return std::clamp(i0[a] + d, 0, f.n[a] - 1); };
    float plane[4];
    for (int di = 0; di < 4; ++di) {
        float row[4];
        for (int dj = 0; dj < 4; ++dj) {
            const int i = ci(0, di - 1), j = ci(1, dj - 1);
            row[dj] = monotonicCubic(f.at(i, j, ci(2, -1)), f.at(i, j, ci(2, 0)), f.at(i, j, ci(2, 1)), f.at(i, j, ci(2, 2)), t[2]);
        }
        plane[di] = monotonicCubic(row[0], row[1], row[2], row[3], t[1]);
    }
    return monotonicCubic(plane[0], plane[1], plane[2], plane[3], t[0]);
}

} // namespace sylva::volume::smoke_detail
