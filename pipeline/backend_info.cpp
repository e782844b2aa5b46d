// Backend summary for `sylva --version` and logs.
#include "pipeline/backend_info.h"

#include <thread>

#include "cuda/device_query.h"

namespace sylva {

std::string backendSummary()
{
    std::string s = "cpu (" + std::to_string(std::thread::hardware_concurrency()) + " threads)";
    const cuda::DeviceQuery q = cuda::queryDevices();
    if (q.devices.empty()) s += "; cuda: " + q.message;
    for (const auto& d : q.devices)
        s += "; cuda " + std::to_string(d.index) + ": " + d.name + " (sm_" + std::to_string(d.computeMajor) +
             std::to_string(d.computeMinor) + ")";
    return s;
}

} // namespace sylva
