// Asks the CUDA runtime which devices exist; any runtime error means "no device" (CPU fallback).
#pragma once

#include <string>
#include <vector>

namespace sylva::cuda {

struct DeviceInfo {
    int index = 0;
    std::string name;
    int computeMajor = 0, computeMinor = 0;
    size_t totalMemoryBytes = 0;
    int multiprocessors = 0;
};

struct DeviceQuery {
    bool built = false;                // this binary contains the CUDA backend
    std::vector<DeviceInfo> devices;   // empty when no usable device
    std::string message;               // why there is no device, when there is none
};

DeviceQuery queryDevices();

} // namespace sylva::cuda
