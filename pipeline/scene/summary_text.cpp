// Numbers for people (summary_text.h).
#include "pipeline/scene/summary_text.h"

#include <cmath>
#include <cstdio>

namespace sylva {

std::string human(double v)
{
    char buf[64];
    if (v != 0.0 && (std::fabs(v) < 1e-3 || std::fabs(v) >= 1e9)) {
        std::snprintf(buf, sizeof buf, "%.4g", v);
        return buf;
    }
    std::snprintf(buf, sizeof buf, "%.3f", v);
    std::string t = buf;
    t.erase(t.find_last_not_of('0') + 1);
    if (t.back() == '.') t.pop_back();
    return t == "-0" ? "0" : t;
}

} // namespace sylva
