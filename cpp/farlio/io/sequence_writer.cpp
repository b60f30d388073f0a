#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "farlio/io/file_bytes.hpp"
#include "farlio/io/imu_csv.hpp"
#include "farlio/io/sequence.hpp"
#include "farlio/io/text_number.hpp"
#include "farlio/io/trajectory_io.hpp"

namespace farlio::io {
namespace {

constexpr std::size_t kKittiNameBytes = 32;  // "%06zu.bin" with room for any size_t

}  // namespace

SequenceWriter::SequenceWriter(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::filesystem::create_directories(dir_);
}

void SequenceWriter::write_calibration(const Calibration& calib) { io::write_calibration(dir_ / "calib.yaml", calib); }

void SequenceWriter::write_scan(const Scan& scan, PcdEncoding encoding) {
  const auto lidar = dir_ / "lidar";
  std::filesystem::create_directories(lidar);
  write_pcd(lidar / (std::to_string(scan.end_stamp_ns) + ".pcd"), scan, encoding);
}

void SequenceWriter::write_imu(const std::vector<ImuSample>& samples) { write_imu_csv(dir_ / "imu.csv", samples); }

void SequenceWriter::write_groundtruth(const Trajectory& body_poses) {
  write_tum(dir_ / "groundtruth.tum", body_poses);
}

void SequenceWriter::write_groundtruth_scans(const Trajectory& body_poses_at_scan_end) {
  write_tum(dir_ / "groundtruth_scans.tum", body_poses_at_scan_end);
}

void SequenceWriter::write_groundtruth_kitti(const Trajectory& lidar_poses_at_scan_end) {
  Trajectory relative;
  if (!lidar_poses_at_scan_end.empty()) {
    const SE3 first_inv = lidar_poses_at_scan_end[0].pose.inverse();
    for (const auto& p : lidar_poses_at_scan_end) relative.push_back(p.stamp_ns, first_inv * p.pose);
  }
  write_kitti(dir_ / "groundtruth_kitti.txt", relative);
}

void SequenceWriter::write_kitti_scan(const Scan& scan, std::size_t index) {
  const auto velodyne = dir_ / "velodyne";
  std::filesystem::create_directories(velodyne);
  std::array<char, kKittiNameBytes> name{};
  std::snprintf(name.data(), name.size(), "%06zu.bin", index);
  write_kitti_bin(velodyne / name.data(), scan);
}

void SequenceWriter::write_kitti_times(const std::vector<std::int64_t>& scan_stamps_ns) {
  std::string text;
  for (auto s : scan_stamps_ns) text += format_seconds_from_ns(s - scan_stamps_ns.front()) + "\n";
  write_text_file(dir_ / "times.txt", text);
}

void SequenceWriter::write_meta(const std::map<std::string, std::string>& meta) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  for (const auto& [k, v] : meta) e << YAML::Key << k << YAML::Value << v;
  e << YAML::EndMap;
  write_text_file(dir_ / "meta.yaml", std::string(e.c_str()) + "\n");
}

}  // namespace farlio::io
