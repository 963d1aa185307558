/// @file cuda_device.h
/// @brief Which CUDA device is present, and a description of it for provenance.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace sdf::cuda {

/// Number of usable CUDA devices; 0 when there is no driver or no GPU (never throws).
int device_count();

/// Index (the ordinal among the visible devices), name, PCI bus id (which physical GPU,
/// whatever CUDA_VISIBLE_DEVICES renumbered), compute capability, memory, SM count, driver and runtime versions of `device`.
nlohmann::json describe_device(int device = 0);

}  // namespace sdf::cuda
