// A number in an error message, one way for the whole core (the LB parameters' and the smoke's checks).
#pragma once

#include <cstdio>
#include <string>

namespace sylva {

// Significant digits that tell any two floats apart: a float one step past a bound reads past it
// ("sigma_t = 1.00000012 exceeds ... 1", not "1 exceeds ... 1").
inline constexpr int kFloatDigits = 9;

// v to `digits` significant digits, as printf's %g writes it: numberText(0.1f) is "0.1" (6 digits hide a
// float's conversion), numberText(1.0000001f, kFloatDigits) is "1.00000012".
inline std::string numberText(double v, int digits = 6)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

} // namespace sylva
