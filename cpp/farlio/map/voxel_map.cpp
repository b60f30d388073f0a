#include "farlio/map/voxel_map.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/error.hpp"

namespace farlio::map {
namespace {
constexpr const char* kCapacityParameter = "map.max_voxel_capacity";
/// Voxels per task of the per-voxel loops: a voxel holds 1 to N_max points, so tasks of a few
/// voxels balance the threads (a map of a few hundred voxels would otherwise make 2 or 3 tasks).
constexpr std::size_t kVoxelGrain = 8;
}  // namespace

double point_spacing_m(const VoxelMapConfig& config) {
  return config.point_spacing_m > 0.0
             ? config.point_spacing_m
             : config.voxel_size_m / std::sqrt(static_cast<double>(config.max_points_per_voxel));
}

VoxelMap::VoxelMap(const VoxelMapConfig& config, exec::CpuExecutor& executor)
    : config_(config), executor_(&executor), spacing_m_(static_cast<float>(point_spacing_m(config))) {
  validate_config(config);
  reserve_voxels(static_cast<std::size_t>(config.initial_voxel_capacity));
  rehash(table_capacity_for(voxel_capacity()));
}

template <typename View, typename Self>
View VoxelMap::view_of(Self& self) {
  return make_map_view<View>(self.slot_keys_.data(), self.slot_voxels_.data(), self.slot_keys_.size(),
                             self.voxel_keys_.data(), self.voxel_counts_.data(), self.points_.data(), self.covs_.data(),
                             self.config_.max_points_per_voxel, self.config_.voxel_size_m);
}

MapView VoxelMap::view() { return view_of<MapView>(*this); }
ConstMapView VoxelMap::view() const { return view_of<ConstMapView>(*this); }

PoolCounts VoxelMap::counts() const {
  return {high_water_, free_voxels_.size(), live_voxels_, used_slots_, slot_keys_.size()};
}

void VoxelMap::reserve_voxels(std::size_t needed) {
  const std::size_t cap = grown_pool_capacity(needed, voxel_keys_.size(),
                                              static_cast<std::size_t>(config_.max_voxel_capacity), kCapacityParameter);
  if (cap == voxel_keys_.size()) return;
  const auto n = static_cast<std::size_t>(config_.max_points_per_voxel);
  voxel_keys_.resize(cap, kEmptyKey);
  voxel_counts_.resize(cap, 0);
  points_.resize(cap * n, Eigen::Vector4f::Zero());
  covs_.resize(cap * n);
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

InsertStats VoxelMap::insert(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin,
                             const PointLimit& limit, CovarianceUpdate covariances) {
  InsertStats stats;
  stats.candidates = points.size();
  const std::size_t groups = group_candidates(points);
  stats.out_of_range = grouping_.dropped();
  std::vector<std::int32_t> group_voxel(groups);
  stats.new_voxels = find_or_add_voxels(group_voxel);
  std::vector<std::int32_t> first_new(groups);
  std::vector<GroupStats> gstats(groups);
  insert_groups(points, origin, limit, group_voxel, first_new, gstats);
  const bool refresh = config_.refresh_covariances;
  const bool compute = covariances == CovarianceUpdate::Compute;
  for (std::size_t g = 0; g < groups; ++g) {
    const GroupStats& s = gstats[g];
    stats.inserted += static_cast<std::size_t>(s.inserted);
    stats.rejected_spacing += static_cast<std::size_t>(s.spacing);
    stats.rejected_full += static_cast<std::size_t>(s.full);
    if (compute) {
      stats.covariances_computed += static_cast<std::size_t>(
          covariance_points(voxel_counts_[static_cast<std::size_t>(group_voxel[g])], first_new[g], refresh).size());
    }
  }
  if (compute) update_group_covariances(group_voxel, first_new, refresh);
  return stats;
}

std::size_t VoxelMap::group_candidates(const std::vector<Eigen::Vector3f>& points) {
  const float inv_voxel = static_cast<float>(1.0 / config_.voxel_size_m);
  keys_.resize(points.size());
  executor_->for_each(points.size(), [&](std::size_t i) { keys_[i] = point_key(points[i], inv_voxel); });
  return grouping_.group(keys_.data(), keys_.size());
}

std::size_t VoxelMap::find_or_add_voxels(std::vector<std::int32_t>& group_voxel) {
  const std::size_t groups = group_voxel.size();
  {
    const ConstMapView v = view();
    executor_->for_each(groups, [&](std::size_t g) {
      const std::uint64_t key = grouping_.key(g);
      group_voxel[g] = table_find(v, key, spatial_hash(unpack_key(key)));
    });
  }
  const auto missing = static_cast<std::size_t>(std::count(group_voxel.begin(), group_voxel.end(), -1));
  if (missing == 0) return 0;
  reserve_voxels(voxels_needed(counts(), missing));
  const InsertionPlan plan = plan_insertion(counts(), missing, voxel_capacity(), kCapacityParameter);
  if (plan.rehash_slots > 0) rehash(plan.rehash_slots);
  const MapView v = view();
  std::int32_t rank = 0;
  for (std::size_t g = 0; g < groups; ++g) {
    if (group_voxel[g] >= 0) continue;
    const std::uint64_t key = grouping_.key(g);
    const std::int32_t vox =
        new_voxel_slot(rank++, free_voxels_.data(), free_voxels_.size(), plan.from_free_list, high_water_);
    group_voxel[g] = vox;
    if (!add_voxel(v, key, vox)) {
      throw CapacityError("voxel map hash table is full (" + std::to_string(slot_keys_.size()) + " slots)");
    }
  }
  free_voxels_.resize(free_voxels_.size() - plan.from_free_list);
  high_water_ = plan.high_water;
  live_voxels_ += missing;
  used_slots_ += missing;
  return missing;
}

void VoxelMap::insert_groups(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin,
                             const PointLimit& limit, const std::vector<std::int32_t>& group_voxel,
                             std::vector<std::int32_t>& first_new, std::vector<GroupStats>& gstats) {
  const InsertParams ip{origin, limit, spacing_m_ * spacing_m_};
  const MapView v = view();
  const std::vector<std::int32_t>& order = grouping_.order();
  const auto candidate = [&](std::int64_t c) {
    return points[static_cast<std::size_t>(order[static_cast<std::size_t>(c)])];
  };
  executor_->for_each(
      group_voxel.size(),
      [&](std::size_t g) {
        gstats[g] = insert_voxel_group(v, group_voxel[g], candidate, static_cast<std::int64_t>(grouping_.start(g)),
                                       static_cast<std::int64_t>(grouping_.start(g + 1)), ip, &first_new[g]);
      },
      kVoxelGrain);
}

void VoxelMap::update_group_covariances(const std::vector<std::int32_t>& group_voxel,
                                        const std::vector<std::int32_t>& first_new, bool refresh) {
  const MapView v = view();
  const int k = config_.covariance_neighbors;
  const auto eps = static_cast<float>(config_.covariance_epsilon);
  const auto line_ratio = static_cast<float>(config_.line_eigenvalue_ratio);
  executor_->for_each(
      group_voxel.size(),
      [&](std::size_t g) {
        const std::int32_t voxel = group_voxel[g];
        const PointRange r = covariance_points(v.voxel_counts[voxel], first_new[g], refresh);
        update_voxel_covariances(v, voxel, r, k, eps, line_ratio);
      },
      kVoxelGrain);
}

std::size_t VoxelMap::remove_far(const Eigen::Vector3f& origin) {
  if (!removal_applies(config_, high_water_)) return 0;
  const double r2 = config_.removal_radius_m * config_.removal_radius_m;
  const MapView v = view();
  std::size_t removed = 0;
  for (std::size_t i = 0; i < high_water_; ++i) {
    const std::uint64_t key = voxel_keys_[i];
    if (!voxel_is_far(key, origin.cast<double>(), r2, config_.voxel_size_m)) continue;
    table_erase(v, key, spatial_hash(unpack_key(key)));
    voxel_keys_[i] = kEmptyKey;
    voxel_counts_[i] = 0;
    free_voxels_.push_back(static_cast<std::int32_t>(i));
    --live_voxels_;
    ++removed;
  }
  if (rehash_after_removal(counts())) rehash(slot_keys_.size());
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
