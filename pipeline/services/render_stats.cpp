// Acceleration structure sizes per triangle and per instance (render_stats.h).
#include "pipeline/services/render_stats.h"

#include <algorithm>

namespace sylva {

AccelSummary summarizeAccel(const AccelStats& st)
{
    AccelSummary s;
    s.totalBytes = double(st.tlasBytes + st.instanceBytes + st.blasBytes + st.triangleBytes + st.wideTlasBytes + st.wideBlasBytes);
    s.bytesPerInstancedTriangle = s.totalBytes / std::max(1.0, st.instancedTriangles);
    s.bytesPerInstance = double(st.tlasBytes + st.instanceBytes) / double(std::max<size_t>(1, st.instances));
    return s;
}

} // namespace sylva
