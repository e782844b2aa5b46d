// Product version string, from the CMake project version.
#include "core/base/version.h"

namespace sylva {
const char* versionString() { return SYLVA_VERSION; }
}
