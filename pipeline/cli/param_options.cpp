// Options from ParamSpecs: their --help line and the parsing of their values.
#include "pipeline/cli/param_options.h"

#include <limits>

#include "pipeline/cli/cli_util.h"

namespace sylva::cli {
namespace {

std::string optionName(const ParamSpec& spec) { return std::string("--") + spec.key; }

// The option's text split into spec.count parts (one part stands for all); empty when absent.
std::vector<std::string> parts(const Args& args, const ParamSpec& spec)
{
    if (!args.has(optionName(spec))) return {};
    const std::string text = args.get(optionName(spec));
    std::vector<std::string> p = spec.count > 1 ? splitList(text) : std::vector<std::string>{text};
    if (p.size() == 1) p.resize(size_t(spec.count), p[0]);
    if (p.size() != size_t(spec.count))
        throw UsageError("option " + optionName(spec) + ": expected " + spec.metavar + " (" + std::to_string(spec.count) +
                         " comma-separated numbers, or one for all), got '" + text + "'");
    return p;
}

std::vector<double> numbers(const Args& args, const ParamSpec& spec)
{
    std::vector<double> v;
    for (const std::string& p : parts(args, spec)) v.push_back(parseNumber(optionName(spec), p));
    return v;
}

// Whole numbers the member's type holds ([lo, hi]). One it cannot hold is outside the parameter's range
// too and is refused as the core refuses one (Error, exit 1); only a parameter without such bounds gets
// parseInteger's UsageError.
std::vector<long long> integers(const Args& args, const ParamSpec& spec, long long lo, long long hi)
{
    std::vector<long long> v;
    for (const std::string& p : parts(args, spec)) {
        const long long x = parseInteger(optionName(spec), p, std::numeric_limits<long long>::min(), std::numeric_limits<long long>::max());
        if (x < lo || x > hi) {
            checkParam(spec, x, "option " + optionName(spec));
            (void)parseInteger(optionName(spec), p, lo, hi);   // throws: outside the type
        }
        v.push_back(x);
    }
    return v;
}

constexpr long long kIntLo = std::numeric_limits<int>::min(), kIntHi = std::numeric_limits<int>::max();

} // namespace

OptionSpec paramOption(const ParamSpec& spec, const std::string& extra)
{
    return {optionName(spec), spec.metavar, paramHelp(spec) + extra};
}

bool readParam(const Args& args, const ParamSpec& spec, double& out)
{
    const std::vector<double> v = numbers(args, spec);
    if (v.empty()) return false;
    out = v[0];
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, float& out)
{
    double d = 0.0;
    if (!readParam(args, spec, d)) return false;
    out = float(d);
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, int& out)
{
    const std::vector<long long> v = integers(args, spec, kIntLo, kIntHi);
    if (v.empty()) return false;
    out = int(v[0]);
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, uint64_t& out)
{
    const std::vector<long long> v = integers(args, spec, 0, std::numeric_limits<long long>::max());
    if (v.empty()) return false;
    out = uint64_t(v[0]);
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, glm::vec2& out)
{
    const std::vector<double> v = numbers(args, spec);
    if (v.empty()) return false;
    out = glm::vec2(float(v[0]), float(v[1]));
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, glm::vec3& out)
{
    const std::vector<double> v = numbers(args, spec);
    if (v.empty()) return false;
    out = glm::vec3(float(v[0]), float(v[1]), float(v[2]));
    return true;
}

bool readParam(const Args& args, const ParamSpec& spec, glm::ivec3& out)
{
    const std::vector<long long> v = integers(args, spec, kIntLo, kIntHi);
    if (v.empty()) return false;
    out = glm::ivec3(int(v[0]), int(v[1]), int(v[2]));
    return true;
}

} // namespace sylva::cli
