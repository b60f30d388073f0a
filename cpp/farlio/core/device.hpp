#pragma once
// Which compute backend runs the scan pipeline: the names of the choices. What the build and the
// machine offer, and what a request resolves to, is pipeline/backend_availability.hpp (it needs
// the CUDA library, which sits above farlio_core).
#include <string>

namespace farlio {

enum class Device { Cpu, Cuda, Auto };

/// "cpu", "cuda" or "auto".
const char* device_name(Device d);
/// Parses "cpu", "cuda" or "auto"; throws std::invalid_argument naming `what` otherwise.
Device parse_device(const std::string& text, const std::string& what = "device");

}  // namespace farlio
