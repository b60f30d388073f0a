#pragma once
// Which compute backend runs the scan pipeline, and what the build and machine offer.
#include <string>

namespace farlio {

enum class Device { Cpu, Cuda, Auto };

/// "cpu", "cuda" or "auto".
const char* device_name(Device d);
/// Parses "cpu", "cuda" or "auto"; throws std::invalid_argument naming `what` otherwise.
Device parse_device(const std::string& text, const std::string& what = "device");

/// True if this build contains the CUDA backend.
bool cuda_compiled();
/// Number of usable CUDA devices (0 without the backend, a driver or a GPU).
int cuda_device_count();
/// Resolves Auto to Cpu or Cuda; `message` explains a fallback. Throws if Cuda is asked for
/// and cannot be had.
Device resolve_device(Device requested, std::string* message = nullptr);

}  // namespace farlio
