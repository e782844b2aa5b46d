// Product version string.
#pragma once

namespace sylva {
const char* versionString();
}
