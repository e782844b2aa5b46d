// The words of a ParamSpec (range, default, help line) and the range checks.
#include "core/base/param_spec.h"

#include <cmath>
#include <cstdio>

#include "core/base/error.h"

namespace sylva {
namespace {

bool isInteger(const ParamSpec& s) { return s.kind == ParamSpec::Kind::Integer; }

std::string mustText(const ParamSpec& s)
{
    const std::string range = paramRange(s);
    return (range[0] == '>' || range[0] == '<' ? "must be " : "must lie in ") + range;
}

} // namespace

bool paramHolds(const ParamSpec& s, double v)
{
    return std::isfinite(v) && (s.loOpen ? v > s.lo : v >= s.lo) && (s.hiOpen ? v < s.hi : v <= s.hi);
}

bool paramHolds(const ParamSpec& s, long long v)
{
    // Integer bounds are whole numbers within +-2^63; compare exactly, not through double.
    if (s.lo != -kUnbounded && (s.loOpen ? v <= (long long)s.lo : v < (long long)s.lo)) return false;
    if (s.hi != kUnbounded && (s.hiOpen ? v >= (long long)s.hi : v > (long long)s.hi)) return false;
    return true;
}

std::string paramNumber(double v)
{
    if (v >= 65536.0 && std::ldexp(1.0, std::ilogb(v)) == v) return "2^" + std::to_string(std::ilogb(v));
    char buf[32];
    if (v == std::trunc(v) && std::fabs(v) < 1e15) {
        std::snprintf(buf, sizeof buf, "%.0f", v);
        return buf;
    }
    std::snprintf(buf, sizeof buf, "%g", v);
    std::string t = buf;
    for (const char* pad : {"e-0", "e+0"}) {
        const size_t at = t.find(pad);
        if (at != std::string::npos) t.erase(at + 2, 1);
    }
    const size_t plus = t.find("e+");
    if (plus != std::string::npos) t.erase(plus + 1, 1);
    return t;
}

std::string paramRange(const ParamSpec& s)
{
    const bool hasLo = s.lo != -kUnbounded, hasHi = s.hi != kUnbounded;
    if (hasLo && hasHi) {
        if (isInteger(s) && !s.loOpen && !s.hiOpen) return paramNumber(s.lo) + ".." + paramNumber(s.hi);
        return std::string(s.loOpen ? "(" : "[") + paramNumber(s.lo) + ", " + paramNumber(s.hi) + (s.hiOpen ? ")" : "]");
    }
    if (hasLo) return std::string(s.loOpen ? "> " : ">= ") + paramNumber(s.lo);
    if (hasHi) return std::string(s.hiOpen ? "< " : "<= ") + paramNumber(s.hi);
    return {};
}

std::string paramDefault(const ParamSpec& s)
{
    std::string t;
    for (int i = 0; i < s.count; ++i) {
        if (i) t += ',';
        t += paramNumber(s.def[i]);
    }
    return t;
}

std::string paramHelp(const ParamSpec& s)
{
    std::string t = s.help;
    if (s.bounded()) t += (s.count > 1 ? ", each " : ", ") + paramRange(s);
    return t + " (default " + paramDefault(s) + ")" + s.note;
}

void checkParam(const ParamSpec& s, double v, const std::string& context, const char* name)
{
    if (!paramHolds(s, v))
        throw Error(context + ": " + (name ? name : s.key) + " " + paramNumber(v) + " " + (std::isfinite(v) ? mustText(s) : "must be finite"));
}

void checkParam(const ParamSpec& s, long long v, const std::string& context, const char* name)
{
    if (!paramHolds(s, v)) throw Error(context + ": " + (name ? name : s.key) + " " + std::to_string(v) + " " + mustText(s));
}

void checkParam(const ParamSpec& s, uint64_t v, const std::string& context, const char* name)
{
    if (v > uint64_t(std::numeric_limits<long long>::max()) || !paramHolds(s, (long long)v))
        throw Error(context + ": " + (name ? name : s.key) + " " + std::to_string(v) + " " + mustText(s));
}

} // namespace sylva
