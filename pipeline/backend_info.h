// One line describing the compute backends available to this process (CPU always, CUDA when present).
#pragma once

#include <string>

namespace sylva {
std::string backendSummary();
}
