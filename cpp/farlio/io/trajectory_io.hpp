#pragma once
// Trajectory files.
//   TUM:   "t x y z qx qy qz qw" per line, t in seconds (written with 9 decimals and converted
//          to and from integer ns exactly); '#' comments and blank lines are allowed.
//   KITTI: 12 numbers per line, the 3x4 row-major [R | t]; no stamps in the file.
// Bad lines throw InputError naming the file and line; unwritable files std::runtime_error.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "farlio/core/trajectory.hpp"

namespace farlio::io {

/// KITTI files hold no stamps: without `stamps_ns` pose i gets stamp i * kKittiDefaultPeriodNs.
inline constexpr std::int64_t kKittiDefaultPeriodNs = 100'000'000;

[[nodiscard]] Trajectory read_tum(const std::filesystem::path& path);
void write_tum(const std::filesystem::path& path, const Trajectory& trajectory);

/// `stamps_ns`, if given, must hold one stamp per pose (else InputError); without it pose i
/// is stamped i * 100 ms.
[[nodiscard]] Trajectory read_kitti(const std::filesystem::path& path,
                                    const std::vector<std::int64_t>* stamps_ns = nullptr);
/// Writes the poses only (KITTI has no stamps).
void write_kitti(const std::filesystem::path& path, const Trajectory& trajectory);

/// Writes a TUM file pose by pose, flushing each line, so a crash loses nothing written.
class TrajectoryWriter {
 public:
  /// Creates (truncates) the file and writes a comment header.
  explicit TrajectoryWriter(const std::filesystem::path& path);
  void append(std::int64_t stamp_ns, const SE3& pose);
  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ofstream out_;
  std::size_t count_ = 0;
};

}  // namespace farlio::io
