#pragma once
// The data model: a LiDAR scan with per-point times and an IMU sample.
// Points are float32 (the hot path); stamps are integer nanoseconds.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "farlio/core/time.hpp"

namespace farlio {

using Vec3f = Eigen::Vector3f;
using Vec3d = Eigen::Vector3d;

/// One LiDAR scan (several LiDARs merged into one frame are still one scan).
struct Scan {
  /// Scan start and end in ns. A point's absolute time is start_stamp_ns + seconds_to_ns(time_s[i]).
  std::int64_t start_stamp_ns = 0;
  std::int64_t end_stamp_ns = 0;
  /// Points in the LiDAR frame at the instant each was measured (raw, motion-distorted).
  std::vector<Vec3f> points;
  /// Per-point time in seconds relative to the scan start; empty means "no per-point time".
  std::vector<float> time_s;
  /// Optional per-point intensity (empty or one per point).
  std::vector<float> intensity;
  /// Optional per-point sensor index for merged multi-LiDAR scans (empty or one per point).
  std::vector<std::uint8_t> sensor_id;

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] bool has_time() const { return !time_s.empty(); }
  [[nodiscard]] double duration_s() const { return ns_to_seconds(end_stamp_ns - start_stamp_ns); }
  /// Throws InputError naming `what` if array sizes disagree or the stamps are inverted.
  void validate(const std::string& what) const;
  /// Whether every coordinate and time is finite.
  [[nodiscard]] bool all_finite() const;
  /// Removes points with a non-finite coordinate or time; returns how many were removed.
  std::size_t remove_non_finite();
};

/// One IMU reading in the IMU (body) frame.
struct ImuSample {
  std::int64_t stamp_ns = 0;
  Vec3d gyro_rad_s = Vec3d::Zero();  ///< angular rate
  Vec3d accel_m_s2 = Vec3d::Zero();  ///< specific force (about +9.81 on z when level at rest)
};

}  // namespace farlio
