#pragma once
// Stamps are integer nanoseconds; durations in the parameter set are seconds. The one place that
// converts between them.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace farlio {

inline constexpr std::int64_t kNsPerSecond = 1'000'000'000;
inline constexpr double kNsPerS = static_cast<double>(kNsPerSecond);

/// Seconds to nanoseconds, rounded to the nearest.
inline std::int64_t seconds_to_ns(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * kNsPerS)); }

/// Nanoseconds (a stamp difference) to seconds.
inline double ns_to_seconds(std::int64_t ns) { return static_cast<double>(ns) / kNsPerS; }

/// Seconds with millisecond resolution ("1700000000.100"), for messages.
inline std::string seconds_text(double seconds) {
  constexpr std::size_t kChars = 64;
  char buf[kChars];
  std::snprintf(buf, kChars, "%.3f", seconds);
  return buf;
}

}  // namespace farlio
