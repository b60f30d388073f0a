#pragma once
// Stamps are integer nanoseconds; durations in the parameter set are seconds.
#include <cmath>
#include <cstdint>

namespace farlio {

inline constexpr double kNsPerS = 1e9;

/// Seconds to nanoseconds, rounded to the nearest.
inline std::int64_t seconds_to_ns(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * kNsPerS)); }

}  // namespace farlio
