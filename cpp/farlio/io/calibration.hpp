#pragma once
// calib.yaml of a sequence folder (see /work/shared/formats/sequence-folder.md), also the
// `--calib` file of recordings that lack an extrinsic:
//   T_imu_lidar: 4x4 row-major nested list, or for several LiDARs a mapping from LiDAR topic
//                (or frame id) to such a matrix (required),
//   gravity (optional), imu: {rate_hz}, lidar: {rate_hz} (optional). Other keys are ignored.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::io {

inline constexpr double kDefaultGravity_m_s2 = 9.81;

struct Calibration {
  SE3 T_imu_lidar;  ///< one LiDAR: maps LiDAR-frame points into the IMU (body) frame
  /// Several LiDARs: LiDAR topic or frame id -> its T_imu_lidar. Empty for one LiDAR; when
  /// not empty it replaces T_imu_lidar (which is then unused).
  std::map<std::string, SE3> T_imu_lidar_by_name;
  std::optional<double> gravity_m_s2;  ///< empty: not stated in the file
  double imu_rate_hz = 0;              ///< 0: not stated
  double lidar_rate_hz = 0;            ///< 0: not stated
  std::filesystem::path source;        ///< the file it was read from (empty if made in code), named in errors

  /// gravity_m_s2, or kDefaultGravity_m_s2 when not stated.
  [[nodiscard]] double gravity_or_default() const { return gravity_m_s2.value_or(kDefaultGravity_m_s2); }
  /// The extrinsic of the LiDAR known by any of `names` (topic, frame id): T_imu_lidar for one
  /// LiDAR, else the entry of the first name found; InputError naming the file, the names and
  /// the entries when none is found.
  [[nodiscard]] const SE3& lidar_extrinsic(const std::vector<std::string>& names) const;
};

/// Throws InputError naming the file (and the key, e.g. T_imu_lidar[/front]) if it is missing,
/// not YAML, lacks T_imu_lidar, or a value is malformed (e.g. not 4x4 or not a rigid transform).
[[nodiscard]] Calibration read_calibration(const std::filesystem::path& path);
/// The same on the text of a file in memory; `path` names it in errors and becomes `source`.
[[nodiscard]] Calibration parse_calibration(const std::string& text, const std::filesystem::path& path);
/// Writes what read_calibration reads back: the mapping form when T_imu_lidar_by_name is not
/// empty, gravity only when stated.
void write_calibration(const std::filesystem::path& path, const Calibration& calib);

}  // namespace farlio::io
