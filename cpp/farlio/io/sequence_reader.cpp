#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/core/time.hpp"
#include "farlio/io/imu_csv.hpp"
#include "farlio/io/point_times.hpp"
#include "farlio/io/sequence.hpp"
#include "farlio/io/text_number.hpp"
#include "farlio/io/trajectory_io.hpp"

namespace farlio::io {
namespace {

/// The file name without its point cloud extension(s): "123.pcd.gz" -> "123".
std::string stem_of(const std::filesystem::path& p) {
  std::string name = p.filename().string();
  constexpr std::string_view kGzip = ".gz";
  if (name.size() > kGzip.size() && name.ends_with(kGzip)) name.resize(name.size() - kGzip.size());
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

std::optional<Trajectory> read_optional_tum(const std::filesystem::path& p) {
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) return std::nullopt;
  return read_tum(p);
}

/// The largest point time of a scan in ns (0 without per-point times).
std::int64_t max_time_ns(const Scan& s) {
  float max_t = 0.0f;
  for (float t : s.time_s) max_t = std::max(max_t, t);
  return seconds_to_ns(static_cast<double>(max_t));
}

}  // namespace

SequenceReader::SequenceReader(std::filesystem::path dir) : dir_(std::move(dir)) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir_, ec)) throw InputError(dir_.string() + ": no such sequence folder");
  list_scans();
  const auto imu_path = dir_ / "imu.csv";
  const auto calib_path = dir_ / "calib.yaml";
  has_imu_ = std::filesystem::exists(imu_path, ec);
  has_calib_ = std::filesystem::exists(calib_path, ec);
  if (has_imu_ && !has_calib_) {
    throw InputError(calib_path.string() + ": missing (required because " + imu_path.string() + " exists)");
  }
  if (has_calib_) calib_ = read_calibration(calib_path);
  if (!calib_.T_imu_lidar_by_name.empty()) {
    throw InputError(calib_path.string() +
                     ": T_imu_lidar is a mapping of several LiDARs; a sequence folder has one "
                     "(a 4x4 matrix)");
  }
  if (has_imu_) imu_ = read_imu_csv(imu_path, warnings_);
}

void SequenceReader::list_scans() {
  const auto lidar = dir_ / "lidar";
  std::error_code ec;
  if (!std::filesystem::is_directory(lidar, ec)) throw InputError(lidar.string() + ": missing lidar folder");
  for (const auto& entry : std::filesystem::directory_iterator(lidar)) {
    const auto& p = entry.path();
    if (!entry.is_regular_file() || !is_point_cloud_file(p)) {
      warnings_.push_back(p.string() + ": not a point cloud file; ignored");
      continue;
    }
    const std::string stem = stem_of(p);
    const auto stamp = std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; })
                           ? parse_int64(stem)
                           : std::nullopt;
    if (!stamp) throw InputError(p.string() + ": file name is not an integer end stamp in ns");
    scans_.push_back({*stamp, p});
  }
  std::sort(scans_.begin(), scans_.end(), [](const ScanFile& a, const ScanFile& b) {
    return a.end_stamp_ns != b.end_stamp_ns ? a.end_stamp_ns < b.end_stamp_ns : a.path < b.path;
  });
  for (std::size_t i = 1; i < scans_.size(); ++i) {
    if (scans_[i].end_stamp_ns == scans_[i - 1].end_stamp_ns) {
      throw InputError(scans_[i].path.string() + ": duplicate scan stamp (also " + scans_[i - 1].path.string() + ")");
    }
  }
}

void SequenceReader::check_index(std::size_t i) const {
  if (i >= scans_.size()) {
    throw std::out_of_range(dir_.string() + ": scan index " + std::to_string(i) + " out of range (" +
                            std::to_string(scans_.size()) + " scans)");
  }
}

std::int64_t SequenceReader::scan_end_stamp_ns(std::size_t i) const {
  check_index(i);
  return scans_[i].end_stamp_ns;
}

const std::filesystem::path& SequenceReader::scan_path(std::size_t i) const {
  check_index(i);
  return scans_[i].path;
}

std::int64_t SequenceReader::scan_start_stamp_ns(std::size_t i) const {
  check_index(i);
  if (scans_.size() > 1) {
    const std::size_t j = i == 0 ? 1 : i;
    return scans_[i].end_stamp_ns - (scans_[j].end_stamp_ns - scans_[j - 1].end_stamp_ns);
  }
  return scans_[i].end_stamp_ns - max_time_ns(read_point_cloud(scans_[i].path));
}

Scan SequenceReader::read_scan(std::size_t i) const {
  check_index(i);
  Scan s = read_point_cloud(scans_[i].path);
  s.end_stamp_ns = scans_[i].end_stamp_ns;
  s.start_stamp_ns = scans_.size() > 1 ? scan_start_stamp_ns(i) : s.end_stamp_ns - max_time_ns(s);
  s.validate(scans_[i].path.string());
  check_point_times(s, scans_[i].path.string());
  return s;
}

std::optional<Trajectory> SequenceReader::groundtruth() const { return read_optional_tum(dir_ / "groundtruth.tum"); }

std::optional<Trajectory> SequenceReader::groundtruth_scans() const {
  return read_optional_tum(dir_ / "groundtruth_scans.tum");
}

}  // namespace farlio::io
