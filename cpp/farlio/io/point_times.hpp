#pragma once
// The check of per-point times, one for every way scans are loaded: the sequence folder
// (SequenceReader), the Python folder loaders (point cloud folders, KITTI, MulRan) and, for the
// span, the PointCloud2 decoder of the bag loader and the ROS 2 node.
//
// Scan::time_s is seconds since the scan start. Times that cannot be that are rejected with an
// InputError naming the scan's file and what was found:
//   * a span (largest minus smallest time) over kMaxScanSpan_s: a unit read wrong, e.g.
//     nanoseconds or microseconds stored in a float field that is read as seconds;
//   * times before the scan start (negative), beyond a small tolerance;
//   * times past the scan's duration (end minus start stamp) beyond the same tolerance, e.g.
//     times spanning 5 scan periods, or absolute (Unix) times.
// Non-finite times are ignored here (the runner drops those points).
#include <span>
#include <string>

#include "farlio/core/types.hpp"

namespace farlio::io {

/// No LiDAR scan lasts longer: a longer span of per-point times means a misread unit.
inline constexpr double kMaxScanSpan_s = 1.0;
/// Times may stray outside [0, duration] by this fraction of the duration (stamp jitter)...
inline constexpr double kPointTimeToleranceFraction = 0.1;
/// ... or by this much, whichever is larger (float rounding, scans without a duration).
inline constexpr double kPointTimeToleranceMin_s = 1e-3;

/// Whether per-point times spanning `span_s` seconds can belong to one scan (finite, at most
/// kMaxScanSpan_s). The rule of the span, shared by check_point_times and the bag loader.
[[nodiscard]] bool point_time_span_plausible(double span_s);

/// What is wrong with the per-point times `time_s` (seconds since the start) of a scan lasting
/// `duration_s` (<= 0: unknown, then only the span and the sign are checked); empty when nothing.
[[nodiscard]] std::string point_time_problem(std::span<const float> time_s, double duration_s);

/// Throws InputError "<what>: <problem>" when point_time_problem finds one in `scan`.
void check_point_times(const Scan& scan, const std::string& what);

}  // namespace farlio::io
