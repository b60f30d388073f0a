#pragma once
// Trajectory files.
//   TUM:   "t x y z qx qy qz qw" per line, t in seconds (written with 9 decimals and converted
//          to and from integer ns exactly); '#' comments and blank lines are allowed.
//   KITTI: 12 numbers per line, the 3x4 row-major [R | t]; no stamps in the file.
//   times: seconds a line (a KITTI times.txt, scan stamps), converted to integer ns exactly.
// Bad lines throw InputError naming the file and line; unwritable files std::runtime_error
// naming the file and the reason ("No space left on device").
//
// A torn last line (the file does not end with a newline and its last line does not parse, as a
// run that died or filled the disk mid-line leaves it) is skipped with a warning naming the file
// and line, into `warnings` when given, else to std::cerr. A bad line anywhere else is an error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "farlio/core/trajectory.hpp"
#include "farlio/io/file_bytes.hpp"

namespace farlio::io {

/// KITTI files hold no stamps: without `stamps_ns` pose i gets stamp i * kKittiDefaultPeriodNs.
inline constexpr std::int64_t kKittiDefaultPeriodNs = 100'000'000;

/// Where the readers put their warnings (a torn last line); nullptr: std::cerr.
using Warnings = std::vector<std::string>;

[[nodiscard]] Trajectory read_tum(const std::filesystem::path& path, Warnings* warnings = nullptr);
void write_tum(const std::filesystem::path& path, const Trajectory& trajectory);

/// `stamps_ns`, if given, must hold one stamp per pose (else InputError; one more is accepted
/// when a torn last line was skipped); without it pose i is stamped i * 100 ms.
[[nodiscard]] Trajectory read_kitti(const std::filesystem::path& path,
                                    const std::vector<std::int64_t>* stamps_ns = nullptr, Warnings* warnings = nullptr);
/// Writes the poses only (KITTI has no stamps).
void write_kitti(const std::filesystem::path& path, const Trajectory& trajectory);

/// A times file: the first field of every line that is not blank or a '#' comment (fields are
/// separated by whitespace or commas), seconds converted to ns by parse_seconds_to_ns (exact for
/// plain decimals). InputError naming file:line for a field that is not a number of seconds, or
/// naming the file when it holds no stamp.
[[nodiscard]] std::vector<std::int64_t> read_stamps(const std::filesystem::path& path, Warnings* warnings = nullptr);

/// The readers on text in memory (or any stream); `file` names it in errors and warnings.
[[nodiscard]] Trajectory parse_tum(std::istream& in, const std::string& file, Warnings* warnings = nullptr);
[[nodiscard]] Trajectory parse_kitti(std::istream& in, const std::string& file,
                                     const std::vector<std::int64_t>* stamps_ns = nullptr,
                                     Warnings* warnings = nullptr);
[[nodiscard]] std::vector<std::int64_t> parse_stamps(std::istream& in, const std::string& file,
                                                     Warnings* warnings = nullptr);

enum class TrajectoryFormat { kAuto, kTum, kKitti };
/// The names of the formats, as the command line and Python take them.
inline constexpr std::array<std::pair<std::string_view, TrajectoryFormat>, 3> kTrajectoryFormatNames{
    {{"auto", TrajectoryFormat::kAuto}, {"tum", TrajectoryFormat::kTum}, {"kitti", TrajectoryFormat::kKitti}}};
/// The format called `name` (kTrajectoryFormatNames); nullopt for any other name.
[[nodiscard]] std::optional<TrajectoryFormat> parse_trajectory_format(std::string_view name);

/// kTum or kKitti by the number of values on the first data line (8 or 12); InputError naming
/// the file (and line) when it is neither or the file holds no pose.
[[nodiscard]] TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path);

/// A TUM or KITTI file (kAuto: detect_trajectory_format). KITTI poses are stamped from
/// `kitti_times` (read_stamps) when given, else i * kKittiDefaultPeriodNs; TUM files ignore it.
[[nodiscard]] Trajectory read_trajectory(const std::filesystem::path& path,
                                         TrajectoryFormat format = TrajectoryFormat::kAuto,
                                         const std::optional<std::filesystem::path>& kitti_times = std::nullopt,
                                         Warnings* warnings = nullptr);

/// Writes a TUM file (or a KITTI file: the poses only) pose by pose, flushing each line, so a
/// crash loses nothing written. A failed write throws std::runtime_error naming the file and the
/// reason.
class TrajectoryWriter {
 public:
  /// Creates (truncates) the file and writes a comment header (TUM only); `format` kTum or kKitti.
  explicit TrajectoryWriter(const std::filesystem::path& path, TrajectoryFormat format = TrajectoryFormat::kTum);
  void append(std::int64_t stamp_ns, const SE3& pose);
  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] const std::filesystem::path& path() const { return out_.path(); }

 private:
  OutputFile out_;
  bool kitti_;
  std::size_t count_ = 0;
};

}  // namespace farlio::io
