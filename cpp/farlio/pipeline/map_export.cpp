#include "farlio/pipeline/map_export.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>

#include "farlio/map/voxel_key.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/preprocess_point.hpp"

namespace farlio::pipeline {
namespace {

/// One cell in a tile's file: its key and its sums.
struct CellRecord {
  std::uint64_t key;
  float dx, dy, dz, intensity;
  std::uint32_t count;
};

}  // namespace

double export_resolution_m(const Config& config) {
  return config.map.export_resolution_m > 0.0 ? config.map.export_resolution_m : map::point_spacing_m(config.map);
}

MapExport::MapExport(double resolution_m, const PreprocessConfig& preprocess, int num_threads,
                     std::filesystem::path spill_dir, double tile_m)
    : resolution_m_(resolution_m),
      preprocess_(preprocess),
      executor_(num_threads),
      spill_dir_(std::move(spill_dir)),
      tile_m_(tile_m),
      reach_m_(preprocess.max_range_m + 0.5 * std::sqrt(3.0) * tile_m) {
  if (!(resolution_m >= kMinVoxelSize_m && resolution_m <= kMaxVoxelSize_m)) {
    throw std::invalid_argument("map export resolution must be in [" + std::to_string(kMinVoxelSize_m) + ", " +
                                std::to_string(kMaxVoxelSize_m) + "] m, got " + std::to_string(resolution_m));
  }
  if (!(tile_m >= resolution_m) || !std::isfinite(tile_m)) {
    throw std::invalid_argument("map export tile must be finite and at least the resolution (" +
                                std::to_string(resolution_m) + " m), got " + std::to_string(tile_m));
  }
  if (!spill_dir_.empty()) std::filesystem::create_directories(spill_dir_);
}

MapExport::~MapExport() {
  std::error_code ignored;
  for (const auto& [tile, n] : tiles_on_disk_) std::filesystem::remove(tile_path(tile), ignored);
  if (!spill_dir_.empty()) std::filesystem::remove(spill_dir_, ignored);  // only when empty
}

std::uint64_t MapExport::tile_of(std::uint64_t cell_key) const {
  const Eigen::Vector3d corner = map::unpack_key(cell_key).cast<double>() * resolution_m_;
  const Eigen::Vector3d t = (corner / tile_m_).array().floor();
  return map::pack_key(t.cast<int>());
}

Eigen::Vector3d MapExport::tile_center(std::uint64_t tile_key) const {
  return (map::unpack_key(tile_key).cast<double>().array() + 0.5) * tile_m_;
}

std::filesystem::path MapExport::tile_path(std::uint64_t tile_key) const {
  return spill_dir_ / ("tile_" + std::to_string(tile_key) + ".bin");
}

std::size_t MapExport::add(const Scan& scan, const deskew::ScanMotion& motion, bool undistort, const SE3& pose) {
  const Eigen::Vector3d sensor = pose.translation();
  if (!spill_dir_.empty()) reload_near(sensor);
  const bool deskew = undistort && scan.has_time();
  // the cell size is not used here: only the crop and undistorted_point
  const preprocess::PreprocessParams pp{preprocess::RangeCrop::from(preprocess_),
                                        deskew::DeskewTable::sample(motion, static_cast<float>(scan.duration_s())),
                                        deskew, 1.0f};
  const Eigen::Matrix3d R = pose.rotation();
  const auto inv_cell = static_cast<float>(1.0 / resolution_m_);
  const bool has_intensity = scan.intensity.size() == scan.size();
  const std::size_t n = scan.size();
  keys_.resize(n);
  offsets_.resize(n);
  // per point, in parallel: crop, undistortion, world position, its cell and the offset in it
  executor_.for_each(n, [&](std::size_t i) {
    keys_[i] = map::kEmptyKey;
    if (!pp.crop.keeps(scan.points[i])) return;
    const Eigen::Vector3f p = preprocess::undistorted_point(scan.points[i], deskew ? scan.time_s[i] : 0.0f, pp);
    const Eigen::Vector3d w = R * p.cast<double>() + sensor;
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
      const auto [it, inserted] = cells_.try_emplace(last_key);
      if (inserted && !spill_dir_.empty()) ++tile_cells_[tile_of(last_key)];
      cell = &it->second;
    }
    cell->dx += offsets_[i].x();
    cell->dy += offsets_[i].y();
    cell->dz += offsets_[i].z();
    cell->intensity += has_intensity ? scan.intensity[i] : 0.0f;
    ++cell->count;
    ++added;
  }
  points_added_ += added;
  if (!spill_dir_.empty()) spill_far(sensor);
  return added;
}

void MapExport::reload_near(const Eigen::Vector3d& sensor) {
  std::vector<std::uint64_t> near;
  for (const auto& [tile, n] : tiles_on_disk_) {
    if ((tile_center(tile) - sensor).norm() <= reach_m_) near.push_back(tile);
  }
  for (const std::uint64_t tile : near) {
    Cells back = read_tile(tile);
    tile_cells_[tile] = back.size();
    cells_on_disk_ -= back.size();
    cells_.merge(back);  // the tile's cells are not in memory (a cell lives in one place)
    tiles_on_disk_.erase(tile);
    std::filesystem::remove(tile_path(tile));
  }
}

void MapExport::spill_far(const Eigen::Vector3d& sensor) {
  std::unordered_map<std::uint64_t, std::vector<CellRecord>> leaving;
  for (const auto& [tile, n] : tile_cells_) {
    if ((tile_center(tile) - sensor).norm() > reach_m_ + tile_m_) leaving[tile];  // a tile of hysteresis
  }
  if (leaving.empty()) return;
  for (auto it = cells_.begin(); it != cells_.end();) {
    const auto out = leaving.find(tile_of(it->first));
    if (out == leaving.end()) {
      ++it;
      continue;
    }
    const Cell& c = it->second;
    out->second.push_back({it->first, c.dx, c.dy, c.dz, c.intensity, c.count});
    it = cells_.erase(it);
  }
  for (const auto& [tile, records] : leaving) {
    const std::filesystem::path path = tile_path(tile);
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(records.data()),
            static_cast<std::streamsize>(records.size() * sizeof(CellRecord)));
    if (!f) throw std::runtime_error(path.string() + ": write error (map export tile)");
    tiles_on_disk_[tile] = records.size();
    cells_on_disk_ += records.size();
    tile_cells_.erase(tile);
  }
}

MapExport::Cells MapExport::read_tile(std::uint64_t tile_key) const {
  const std::filesystem::path path = tile_path(tile_key);
  const std::size_t n = tiles_on_disk_.at(tile_key);
  std::vector<CellRecord> records(n);
  std::ifstream f(path, std::ios::binary);
  f.read(reinterpret_cast<char*>(records.data()), static_cast<std::streamsize>(n * sizeof(CellRecord)));
  if (!f) throw std::runtime_error(path.string() + ": cannot read back (map export tile)");
  Cells cells;
  cells.reserve(n);
  for (const CellRecord& r : records) cells.emplace(r.key, Cell{r.dx, r.dy, r.dz, r.intensity, r.count});
  return cells;
}

void MapExport::emit(const Cells& cells,
                     const std::function<void(std::span<const Vec3f>, std::span<const float>)>& piece) const {
  std::vector<std::uint64_t> keys;
  keys.reserve(cells.size());
  for (const auto& [key, cell] : cells) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  std::vector<Vec3f> points;
  std::vector<float> intensity;
  points.reserve(keys.size());
  intensity.reserve(keys.size());
  for (const std::uint64_t key : keys) {
    const Cell& c = cells.at(key);
    const Eigen::Vector3d corner = map::unpack_key(key).cast<double>() * resolution_m_;
    const double n = c.count;
    points.push_back((corner + Eigen::Vector3d(c.dx / n, c.dy / n, c.dz / n)).cast<float>());
    intensity.push_back(static_cast<float>(c.intensity / n));
  }
  piece(points, intensity);
}

void MapExport::for_each_piece(const std::function<void(std::span<const Vec3f>, std::span<const float>)>& piece) const {
  emit(cells_, piece);
  std::vector<std::uint64_t> tiles;
  for (const auto& [tile, n] : tiles_on_disk_) tiles.push_back(tile);
  std::sort(tiles.begin(), tiles.end());
  for (const std::uint64_t tile : tiles) emit(read_tile(tile), piece);
}

Scan MapExport::points() const {
  Scan out;
  for_each_piece([&](std::span<const Vec3f> p, std::span<const float> i) {
    out.points.insert(out.points.end(), p.begin(), p.end());
    out.intensity.insert(out.intensity.end(), i.begin(), i.end());
  });
  return out;
}

std::size_t MapExport::memory_bytes() const {
  // an unordered_map node holds the entry and the next pointer (and, in libstdc++, no cached hash
  // for integer keys); the buckets are one pointer each
  constexpr std::size_t kNodeBytes = sizeof(std::pair<const std::uint64_t, Cell>) + sizeof(void*);
  return cells_.size() * kNodeBytes + cells_.bucket_count() * sizeof(void*);
}

}  // namespace farlio::pipeline
