#include "farlio/map/voxel_map.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/map/voxel_update.hpp"

namespace farlio::map {
namespace {
std::size_t next_pow2(std::size_t n) { return std::bit_ceil(std::max<std::size_t>(n, 16)); }
}  // namespace

double point_spacing_m(const VoxelMapConfig& config) {
  return config.point_spacing_m > 0.0 ? config.point_spacing_m
                                      : config.voxel_size_m / std::sqrt(static_cast<double>(config.max_points_per_voxel));
}

std::size_t table_capacity_for(std::size_t voxel_capacity) { return next_pow2(kSlotsPerVoxel * voxel_capacity); }

void validate_map_config(const VoxelMapConfig& config) {
  if (config.voxel_size_m <= 0 || config.max_points_per_voxel <= 0 || config.covariance_neighbors <= 0 ||
      config.covariance_neighbors > kMaxNeighbors) {
    throw std::invalid_argument("VoxelMap: voxel_size_m and max_points_per_voxel must be > 0 and "
                                "covariance_neighbors in [1, " + std::to_string(kMaxNeighbors) + "]");
  }
}

VoxelMap::VoxelMap(const VoxelMapConfig& config, exec::CpuExecutor& executor)
    : config_(config),
      executor_(&executor),
      spacing_m_(static_cast<float>(point_spacing_m(config))) {
  validate_map_config(config);
  reserve_voxels(static_cast<std::size_t>(std::max<std::int64_t>(config.initial_voxel_capacity, 1)));
}

MapView VoxelMap::view() const {
  auto* self = const_cast<VoxelMap*>(this);  // the view is the kernels' mutable window
  MapView v;
  v.slot_keys = self->slot_keys_.data();
  v.slot_voxels = self->slot_voxels_.data();
  v.table_capacity = slot_keys_.size();
  v.voxel_keys = self->voxel_keys_.data();
  v.voxel_counts = self->voxel_counts_.data();
  v.points = self->points_.data();
  v.covs = self->covs_.data();
  v.max_points_per_voxel = config_.max_points_per_voxel;
  v.voxel_size = static_cast<float>(config_.voxel_size_m);
  v.inv_voxel_size = static_cast<float>(1.0 / config_.voxel_size_m);
  return v;
}

void VoxelMap::reserve_voxels(std::size_t needed) {
  const std::size_t cap = voxel_keys_.size();
  if (needed > cap) {
    const auto max_cap = static_cast<std::size_t>(config_.max_voxel_capacity);
    if (needed > max_cap) {
      throw CapacityError("voxel map is full: " + std::to_string(needed) + " voxels needed, map.max_voxel_capacity is " +
                          std::to_string(max_cap) + "; raise it or lower map.removal_radius_m");
    }
    const std::size_t new_cap = std::min(max_cap, std::max(needed, 2 * cap));
    const auto n = static_cast<std::size_t>(config_.max_points_per_voxel);
    voxel_keys_.resize(new_cap, kEmptyKey);
    voxel_counts_.resize(new_cap, 0);
    points_.resize(new_cap * n, Eigen::Vector4f::Zero());
    covs_.resize(new_cap * n);
  }
  if (slot_keys_.size() < kSlotsPerVoxel * voxel_keys_.size()) rehash(table_capacity_for(voxel_keys_.size()));
}

void VoxelMap::rehash(std::size_t slots) {
  slot_keys_.assign(slots, kEmptyKey);
  slot_voxels_.assign(slots, -1);
  const MapView v = view();
  for (std::size_t i = 0; i < high_water_; ++i) {
    const std::uint64_t key = voxel_keys_[i];
    if (key == kEmptyKey) continue;
    table_insert(v, key, spatial_hash(unpack_key(key)), static_cast<std::int32_t>(i));
  }
  used_slots_ = live_voxels_;
}

void VoxelMap::set_table_capacity_for_testing(std::size_t slots) { rehash(std::bit_ceil(slots)); }

std::int32_t VoxelMap::allocate_voxel(std::uint64_t key) {
  std::int32_t v;
  if (!free_voxels_.empty()) {
    v = free_voxels_.back();
    free_voxels_.pop_back();
  } else {
    v = static_cast<std::int32_t>(high_water_++);
  }
  voxel_keys_[static_cast<std::size_t>(v)] = key;
  voxel_counts_[static_cast<std::size_t>(v)] = 0;
  ++live_voxels_;
  return v;
}

InsertStats VoxelMap::insert(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin,
                             const PointLimit& limit) {
  InsertStats stats;
  stats.candidates = points.size();
  const float inv_voxel = static_cast<float>(1.0 / config_.voxel_size_m);

  // 1. group candidates by voxel, in input order inside a voxel
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(points.size());
  executor_->for_each(points.size(), [&](std::size_t i) {
    keyed[i] = {point_key(points[i], inv_voxel), static_cast<std::int32_t>(i)};
  });
  executor_->run([&] { tbb::parallel_sort(keyed.begin(), keyed.end()); });
  while (!keyed.empty() && keyed.back().first == kEmptyKey) {
    keyed.pop_back();
    ++stats.out_of_range;
  }
  std::vector<std::size_t> group_start;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i == 0 || keyed[i].first != keyed[i - 1].first) group_start.push_back(i);
  }
  const std::size_t groups = group_start.size();
  group_start.push_back(keyed.size());

  // 2. find existing voxels, create the missing ones (serially: deterministic pool indices)
  std::vector<std::int32_t> group_voxel(groups);
  {
    const MapView v = view();
    executor_->for_each(groups, [&](std::size_t g) {
      const std::uint64_t key = keyed[group_start[g]].first;
      group_voxel[g] = table_find(v, key, spatial_hash(unpack_key(key)));
    });
  }
  const auto missing = static_cast<std::size_t>(std::count(group_voxel.begin(), group_voxel.end(), -1));
  if (missing > 0) {
    const std::size_t from_pool = std::min(missing, free_voxels_.size());
    reserve_voxels(high_water_ + (missing - from_pool));
    if (static_cast<double>(used_slots_ + missing) > static_cast<double>(slot_keys_.size()) / kSlotsPerVoxel) {
      rehash(next_pow2(2 * slot_keys_.size()));
    }
    const MapView v = view();
    for (std::size_t g = 0; g < groups; ++g) {
      if (group_voxel[g] >= 0) continue;
      const std::uint64_t key = keyed[group_start[g]].first;
      group_voxel[g] = allocate_voxel(key);
      if (table_insert(v, key, spatial_hash(unpack_key(key)), group_voxel[g]) < 0) {
        throw CapacityError("voxel map hash table is full (" + std::to_string(slot_keys_.size()) + " slots)");
      }
      ++used_slots_;
    }
    stats.new_voxels = missing;
  }

  // 3. insert each voxel's candidates in order, with the cap and the spacing
  const InsertParams ip{origin, limit, spacing_m_ * spacing_m_};
  std::vector<std::int32_t> first_new(groups);
  std::vector<GroupStats> gstats(groups);
  {
    const MapView v = view();
    const auto candidate = [&](std::int64_t c) { return points[static_cast<std::size_t>(keyed[static_cast<std::size_t>(c)].second)]; };
    executor_->for_each(groups, [&](std::size_t g) {
      gstats[g] = insert_voxel_group(v, group_voxel[g], candidate, static_cast<std::int64_t>(group_start[g]),
                                     static_cast<std::int64_t>(group_start[g + 1]), ip, &first_new[g]);
    });
  }
  for (const auto& s : gstats) {
    stats.inserted += static_cast<std::size_t>(s.inserted);
    stats.rejected_spacing += static_cast<std::size_t>(s.spacing);
    stats.rejected_full += static_cast<std::size_t>(s.full);
  }

  // 4. covariances of the new points (or of every point of a changed voxel)
  std::vector<std::int32_t> cov_voxels, cov_first;
  for (std::size_t g = 0; g < groups; ++g) {
    const std::int32_t count = voxel_counts_[static_cast<std::size_t>(group_voxel[g])];
    if (count == first_new[g]) continue;
    cov_voxels.push_back(group_voxel[g]);
    cov_first.push_back(config_.refresh_covariances ? 0 : first_new[g]);
    stats.covariances_computed += static_cast<std::size_t>(count - cov_first.back());
  }
  compute_covariances(cov_voxels, cov_first);
  return stats;
}

void VoxelMap::compute_covariances(const std::vector<std::int32_t>& voxels, const std::vector<std::int32_t>& first_point) {
  const MapView v = view();
  const int k = config_.covariance_neighbors;
  const auto eps = static_cast<float>(config_.covariance_epsilon);
  const auto line_ratio = static_cast<float>(config_.line_eigenvalue_ratio);
  executor_->for_each(voxels.size(),
                      [&](std::size_t i) { update_voxel_covariances(v, voxels[i], first_point[i], k, eps, line_ratio); });
}

std::size_t VoxelMap::remove_far(const Eigen::Vector3f& origin) {
  const double r2 = config_.removal_radius_m * config_.removal_radius_m;
  const double vs = config_.voxel_size_m;
  const MapView v = view();
  std::size_t removed = 0;
  for (std::size_t i = 0; i < high_water_; ++i) {
    const std::uint64_t key = voxel_keys_[i];
    if (key == kEmptyKey) continue;
    if (voxel_centre_distance2(key, origin.cast<double>(), vs) <= r2) continue;
    table_erase(v, key, spatial_hash(unpack_key(key)));
    voxel_keys_[i] = kEmptyKey;
    voxel_counts_[i] = 0;
    free_voxels_.push_back(static_cast<std::int32_t>(i));
    --live_voxels_;
    ++removed;
  }
  if (static_cast<double>(used_slots_ - live_voxels_) > kMaxErasedFraction * static_cast<double>(slot_keys_.size())) {
    rehash(slot_keys_.size());
  }
  return removed;
}

void VoxelMap::clear() {
  std::fill(slot_keys_.begin(), slot_keys_.end(), kEmptyKey);
  std::fill(voxel_keys_.begin(), voxel_keys_.begin() + static_cast<std::ptrdiff_t>(high_water_), kEmptyKey);
  std::fill(voxel_counts_.begin(), voxel_counts_.begin() + static_cast<std::ptrdiff_t>(high_water_), 0);
  free_voxels_.clear();
  high_water_ = 0;
  live_voxels_ = 0;
  used_slots_ = 0;
}

std::size_t VoxelMap::num_points() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < high_water_; ++i) n += static_cast<std::size_t>(voxel_counts_[i]);
  return n;
}

std::size_t VoxelMap::memory_bytes() const {
  return slot_keys_.capacity() * sizeof(std::uint64_t) + slot_voxels_.capacity() * sizeof(std::int32_t) +
         voxel_keys_.capacity() * sizeof(std::uint64_t) + voxel_counts_.capacity() * sizeof(std::int32_t) +
         points_.capacity() * sizeof(Eigen::Vector4f) + covs_.capacity() * sizeof(Cov3);
}

MapSnapshot VoxelMap::snapshot() const {
  const auto n = static_cast<std::size_t>(config_.max_points_per_voxel);
  const auto hw = static_cast<std::ptrdiff_t>(high_water_);
  const auto hw_points = static_cast<std::ptrdiff_t>(high_water_ * n);
  MapSnapshot s;
  s.max_points_per_voxel = config_.max_points_per_voxel;
  s.voxel_keys.assign(voxel_keys_.begin(), voxel_keys_.begin() + hw);
  s.voxel_counts.assign(voxel_counts_.begin(), voxel_counts_.begin() + hw);
  s.points.assign(points_.begin(), points_.begin() + hw_points);
  s.covs.assign(covs_.begin(), covs_.begin() + hw_points);
  return s;
}

void VoxelMap::for_each_point(const std::function<void(const Eigen::Vector3f&, const Cov3&, bool)>& f) const {
  snapshot().for_each_point(f);
}

double VoxelMap::mean_points_per_voxel(const Eigen::Vector3f& origin, double range_m) const {
  const double vs = config_.voxel_size_m;
  std::size_t voxels = 0, pts = 0;
  for (std::size_t v = 0; v < high_water_; ++v) {
    if (voxel_keys_[v] == kEmptyKey) continue;
    if (std::sqrt(voxel_centre_distance2(voxel_keys_[v], origin.cast<double>(), vs)) > range_m) continue;
    ++voxels;
    pts += static_cast<std::size_t>(voxel_counts_[v]);
  }
  return voxels ? static_cast<double>(pts) / static_cast<double>(voxels) : 0.0;
}

}  // namespace farlio::map
