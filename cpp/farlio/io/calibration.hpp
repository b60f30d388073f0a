#pragma once
// calib.yaml of a sequence folder (see /work/shared/formats/sequence-folder.md):
//   T_imu_lidar: 4x4 row-major nested list (required), gravity (default 9.81),
//   imu: {rate_hz}, lidar: {rate_hz} (optional). Other keys are ignored.
#include <filesystem>

#include "farlio/core/se3.hpp"

namespace farlio::io {

inline constexpr double kDefaultGravity_m_s2 = 9.81;

struct Calibration {
  SE3 T_imu_lidar;  ///< maps LiDAR-frame points into the IMU (body) frame
  double gravity_m_s2 = kDefaultGravity_m_s2;
  double imu_rate_hz = 0;    ///< 0: not stated
  double lidar_rate_hz = 0;  ///< 0: not stated
};

/// Throws InputError naming the file (and the key) if it is missing, not YAML, lacks
/// T_imu_lidar, or a value is malformed (e.g. T_imu_lidar not 4x4 or not a rigid transform).
[[nodiscard]] Calibration read_calibration(const std::filesystem::path& path);
void write_calibration(const std::filesystem::path& path, const Calibration& calib);

}  // namespace farlio::io
