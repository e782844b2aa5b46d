// Command options declared by a ParamSpec (core/base/param_spec.h): the option and its --help line come
// from the declaration, and the value is read into the struct's member. The range is the core's
// check (validatePyroclastic, validateSmoke, or checkParam where no validation covers it): a value
// outside it exits 1 naming the parameter, a value that is no number exits 2.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/base/param_spec.h"
#include "pipeline/cli/args.h"

namespace sylva::cli {

// {"--KEY", metavar, paramHelp(spec) + extra}.
OptionSpec paramOption(const ParamSpec& spec, const std::string& extra = {});

// When --KEY is given: its spec.count comma-separated numbers (whole numbers for integer specs; one
// number sets every component) into out, and true; false (out untouched) when it is absent. Throws
// UsageError for text that is no such number or list.
bool readParam(const Args& args, const ParamSpec& spec, float& out);
bool readParam(const Args& args, const ParamSpec& spec, double& out);
bool readParam(const Args& args, const ParamSpec& spec, int& out);
bool readParam(const Args& args, const ParamSpec& spec, uint64_t& out);
bool readParam(const Args& args, const ParamSpec& spec, glm::vec2& out);
bool readParam(const Args& args, const ParamSpec& spec, glm::vec3& out);
bool readParam(const Args& args, const ParamSpec& spec, glm::ivec3& out);

} // namespace sylva::cli
