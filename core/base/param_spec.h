// One parameter of a generator or a simulation, declared once beside the struct that holds it: its name,
// type, range, default and one line of help. The struct's member defaults, the core's validation, the
// CLI's options and --help (pipeline/cli/param_options.h), the studio's form widgets
// (studio/param_widgets.h) and the check of docs/CLI.md (tst_docs) all read the same declaration.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace sylva {

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// The largest seed any generator takes: 2^62, exact in a double (a JSON number, a ParamSpec bound) and
// below 2^63 (a signed parse). The scene file's seeds, the CLI's --seed options and the cloud's and smoke's
// seeds all read it here; the docs write it "2^62" (paramNumber).
inline constexpr uint64_t kMaxSeed = uint64_t(1) << 62;

struct ParamSpec {
    enum class Kind { Real, Integer };
    const char* key = "";          // the field's name; the CLI option is --key
    Kind kind = Kind::Real;
    const char* metavar = "";      // --help's placeholder: "R", "N", "X,Y,Z"
    int count = 1;                 // components, given comma-separated (a position: 3)
    double lo = -kUnbounded;       // range of every component; an infinite bound is no bound
    double hi = kUnbounded;
    bool loOpen = false, hiOpen = false;
    double def[3] = {0.0, 0.0, 0.0};   // default of each component
    const char* help = "";         // what it is and its unit, without range or default
    const char* note = "";         // said after the default: "; the same seed gives the same grid"

    bool bounded() const { return lo != -kUnbounded || hi != kUnbounded; }
};

// Whether v lies in the range (NaN and infinities never do).
bool paramHolds(const ParamSpec& s, double v);
bool paramHolds(const ParamSpec& s, long long v);
// The range in words: "1..12" (integers), "> 0", ">= 0", "(0, 1]", "0..2^62"; empty when unbounded.
std::string paramRange(const ParamSpec& s);
// A value as the docs write it: "1", "0.5", "1e-6", "2^62".
std::string paramNumber(double v);
// The default: "1", "64,96,64", "0,0,0".
std::string paramDefault(const ParamSpec& s);
// --help's line: help, range and default: "fBm octaves, 1..12 (default 4)".
std::string paramHelp(const ParamSpec& s);
// Throws sylva::Error "CONTEXT: NAME V must RANGE" (or "must be finite") when v is outside the range;
// NAME is the key unless given.
void checkParam(const ParamSpec& s, double v, const std::string& context, const char* name = nullptr);
void checkParam(const ParamSpec& s, long long v, const std::string& context, const char* name = nullptr);
inline void checkParam(const ParamSpec& s, int v, const std::string& context, const char* name = nullptr)
{
    checkParam(s, (long long)v, context, name);
}
void checkParam(const ParamSpec& s, uint64_t v, const std::string& context, const char* name = nullptr);

} // namespace sylva
