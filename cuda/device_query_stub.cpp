// Device query for builds without nvcc: reports that this build has no CUDA backend.
#include "cuda/device_query.h"

namespace sylva::cuda {

DeviceQuery queryDevices()
{
    DeviceQuery q;
    q.message = "this build has no CUDA backend (configured without CUDA: nvcc missing or older than 12, or SYLVA_ENABLE_CUDA=OFF)";
    return q;
}

} // namespace sylva::cuda
