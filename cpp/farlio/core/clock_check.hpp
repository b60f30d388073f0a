#pragma once
// Do the IMU and the LiDAR run on the same clock, in the same unit? Both are stamped in integer
// ns; a recording whose IMU is stamped in us (or its scans named in us) puts the two spans
// decades apart, and an offset between the two clocks shifts one span against the other. The
// odometry cannot make sense of either, so the spans are compared before a run: spans that do
// not overlap are an error that says what was found (and which unit would make them overlap);
// spans that overlap but start or end far apart are a warning.
#include <cstdint>
#include <string>
#include <vector>

namespace farlio {

/// The first and last stamp of a stream (ns).
struct StampSpan {
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
};

struct ClockCheck {
  std::string error;                  ///< empty when the spans overlap
  std::vector<std::string> warnings;  ///< the IMU starts late / ends early by more than the tolerance
};

/// Compares the IMU's span with the scans' (a span of one stamp: a single scan). The spans
/// overlap when they share an instant within `tolerance_s`; the warnings name the seconds by
/// which the IMU starts after the first scan or ends before the last one, beyond `tolerance_s`.
[[nodiscard]] ClockCheck check_clocks(const StampSpan& imu, const StampSpan& scans, double tolerance_s);

}  // namespace farlio
