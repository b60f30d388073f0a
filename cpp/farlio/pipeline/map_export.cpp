#include "farlio/pipeline/map_export.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "farlio/map/voxel_key.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/preprocess_point.hpp"

namespace farlio::pipeline {

double export_resolution_m(const Config& config) {
  return config.map.export_resolution_m > 0.0 ? config.map.export_resolution_m : map::point_spacing_m(config.map);
}

MapExport::MapExport(double resolution_m, const PreprocessConfig& preprocess, int num_threads)
    : resolution_m_(resolution_m), preprocess_(preprocess), executor_(num_threads) {
  if (!(resolution_m >= kMinVoxelSize_m && resolution_m <= kMaxVoxelSize_m)) {
    throw std::invalid_argument("map export resolution must be in [" + std::to_string(kMinVoxelSize_m) + ", " +
                                std::to_string(kMaxVoxelSize_m) + "] m, got " + std::to_string(resolution_m));
  }
}

std::size_t MapExport::add(const Scan& scan, const deskew::ScanMotion& motion, bool undistort, const SE3& pose) {
  const bool deskew = undistort && scan.has_time();
  // the cell size is not used here: only the crop and the undistortion of preprocess_point
  const PreprocessParams pp{RangeCrop::from(preprocess_), motion, deskew, 1.0f};
  const Eigen::Matrix3d R = pose.rotation();
  const Eigen::Vector3d t = pose.translation();
  const auto inv_cell = static_cast<float>(1.0 / resolution_m_);
  const bool has_intensity = scan.intensity.size() == scan.size();
  const std::size_t n = scan.size();
  keys_.resize(n);
  offsets_.resize(n);
  // per point, in parallel: crop, undistortion, world position, its cell and the offset in it
  executor_.for_each(n, [&](std::size_t i) {
    Eigen::Vector3f p;
    keys_[i] = map::kEmptyKey;
    if (preprocess_point(scan.points[i], deskew ? scan.time_s[i] : 0.0f, pp, &p) == map::kEmptyKey) return;
    const Eigen::Vector3d w = R * p.cast<double>() + t;
    const std::uint64_t key = map::point_key(w.cast<float>(), inv_cell);
    if (key == map::kEmptyKey) return;
    keys_[i] = key;
    offsets_[i] = (w - map::unpack_key(key).cast<double>() * resolution_m_).cast<float>();
  });
  // accumulation in scan order (deterministic); neighbours along a scan line often share a cell
  std::size_t added = 0;
  std::uint64_t last_key = map::kEmptyKey;
  Cell* cell = nullptr;  // unordered_map nodes do not move on a rehash
  for (std::size_t i = 0; i < n; ++i) {
    if (keys_[i] == map::kEmptyKey) continue;
    if (keys_[i] != last_key) {
      last_key = keys_[i];
      cell = &cells_[last_key];
    }
    cell->dx += offsets_[i].x();
    cell->dy += offsets_[i].y();
    cell->dz += offsets_[i].z();
    cell->intensity += has_intensity ? scan.intensity[i] : 0.0f;
    ++cell->count;
    ++added;
  }
  points_added_ += added;
  return added;
}

Scan MapExport::points() const {
  std::vector<std::uint64_t> keys;
  keys.reserve(cells_.size());
  for (const auto& [key, cell] : cells_) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  Scan out;
  out.points.reserve(keys.size());
  out.intensity.reserve(keys.size());
  for (const std::uint64_t key : keys) {
    const Cell& c = cells_.at(key);
    const Eigen::Vector3d corner = map::unpack_key(key).cast<double>() * resolution_m_;
    const double n = c.count;
    out.points.push_back((corner + Eigen::Vector3d(c.dx / n, c.dy / n, c.dz / n)).cast<float>());
    out.intensity.push_back(static_cast<float>(c.intensity / n));
  }
  return out;
}

std::size_t MapExport::memory_bytes() const {
  // an unordered_map node holds the entry and the next pointer (and, in libstdc++, no cached hash
  // for integer keys); the buckets are one pointer each
  constexpr std::size_t kNodeBytes = sizeof(std::pair<const std::uint64_t, Cell>) + sizeof(void*);
  return cells_.size() * kNodeBytes + cells_.bucket_count() * sizeof(void*);
}

}  // namespace farlio::pipeline
