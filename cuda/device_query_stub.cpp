// Device query for builds without nvcc: reports that this build has no CUDA backend.
#include "cuda/device_query.h"

namespace sylva::cuda {

DeviceQuery queryDevices()
{
    DeviceQuery q;
    q.message = "this build has no CUDA backend (nvcc was not found at configure time)";
    return q;
}

} // namespace sylva::cuda
