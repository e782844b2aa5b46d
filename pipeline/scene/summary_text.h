// Numbers for people in scene summaries (`sylva info`): up to three decimals, trailing zeros dropped.
#pragma once

#include <string>

namespace sylva {

// Up to three decimals, trailing zeros dropped; tiny and huge ones in %g form.
std::string human(double v);

template <class V>
std::string human3(const V& v)
{
    std::string s(1, '(');   // appended: GCC 12 warns falsely (-Wrestrict) on "(" + temporary
    s += human(double(v.x));
    s += ", ";
    s += human(double(v.y));
    s += ", ";
    s += human(double(v.z));
    s += ')';
    return s;
}

} // namespace sylva
