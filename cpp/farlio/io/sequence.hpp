#pragma once
// The sequence folder (/work/shared/formats/sequence-folder.md):
//   lidar/<end_stamp_ns>.pcd (also .pcd.gz, .ply, .bin), imu.csv, calib.yaml,
//   groundtruth.tum, groundtruth_scans.tum, groundtruth_kitti.txt, velodyne/ + times.txt, meta.yaml.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farlio/core/trajectory.hpp"
#include "farlio/core/types.hpp"
#include "farlio/io/calibration.hpp"
#include "farlio/io/point_cloud_io.hpp"

namespace farlio::io {

/// Reads a sequence folder. The constructor lists the scans and reads imu.csv and calib.yaml;
/// scans and ground truth are read on demand. Bad input throws InputError naming the file.
class SequenceReader {
 public:
  explicit SequenceReader(std::filesystem::path dir);

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::size_t num_scans() const { return scans_.size(); }
  /// Throws std::out_of_range for i >= num_scans().
  [[nodiscard]] std::int64_t scan_end_stamp_ns(std::size_t i) const;
  /// The start stamp: end minus the period (difference to the previous end stamp; the first
  /// scan uses the next difference; a lone scan uses its largest point time).
  [[nodiscard]] std::int64_t scan_start_stamp_ns(std::size_t i) const;
  [[nodiscard]] const std::filesystem::path& scan_path(std::size_t i) const;
  /// Scan i with its stamps set; InputError naming its file when its per-point times cannot be
  /// seconds since its start (check_point_times).
  [[nodiscard]] Scan read_scan(std::size_t i) const;

  [[nodiscard]] bool has_imu() const { return has_imu_; }
  [[nodiscard]] const std::vector<ImuSample>& imu() const { return imu_; }
  /// calib.yaml (one 4x4 T_imu_lidar; the mapping form is an error); the defaults (identity
  /// extrinsic, gravity not stated) when the folder has none.
  [[nodiscard]] const Calibration& calibration() const { return calib_; }
  [[nodiscard]] bool has_calibration() const { return has_calib_; }

  /// groundtruth.tum / groundtruth_scans.tum if present (read on each call).
  [[nodiscard]] std::optional<Trajectory> groundtruth() const;
  [[nodiscard]] std::optional<Trajectory> groundtruth_scans() const;

  /// What was tolerated while reading: dropped IMU samples, ignored columns and files.
  [[nodiscard]] std::vector<std::string> warnings() const { return warnings_; }

 private:
  struct ScanFile {
    std::int64_t end_stamp_ns = 0;
    std::filesystem::path path;
  };
  void list_scans();
  void check_index(std::size_t i) const;

  std::filesystem::path dir_;
  std::vector<ScanFile> scans_;
  bool has_imu_ = false;
  std::vector<ImuSample> imu_;
  bool has_calib_ = false;
  Calibration calib_;
  std::vector<std::string> warnings_;
};

/// Writes a sequence folder (created if needed); each call writes one file completely.
class SequenceWriter {
 public:
  explicit SequenceWriter(std::filesystem::path dir);

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  void write_calibration(const Calibration& calib);
  /// lidar/<end_stamp_ns>.pcd
  void write_scan(const Scan& scan, PcdEncoding encoding = PcdEncoding::Binary);
  void write_imu(const std::vector<ImuSample>& samples);
  /// groundtruth.tum: body (IMU) poses.
  void write_groundtruth(const Trajectory& body_poses);
  /// groundtruth_scans.tum: body poses at the scan end stamps.
  void write_groundtruth_scans(const Trajectory& body_poses_at_scan_end);
  /// groundtruth_kitti.txt: LiDAR poses at scan end relative to the first (first = identity).
  void write_groundtruth_kitti(const Trajectory& lidar_poses_at_scan_end);
  /// velodyne/<index as %06d>.bin
  void write_kitti_scan(const Scan& scan, std::size_t index);
  /// times.txt: seconds since the first stamp, one per line, 9 decimals.
  void write_kitti_times(const std::vector<std::int64_t>& scan_stamps_ns);
  /// meta.yaml: free-form key: value pairs.
  void write_meta(const std::map<std::string, std::string>& meta);

 private:
  std::filesystem::path dir_;
};

}  // namespace farlio::io
