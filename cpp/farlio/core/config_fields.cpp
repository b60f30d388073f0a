#include "farlio/core/config_fields.hpp"

#include <algorithm>
#include <charconv>
#include <sstream>
#include <stdexcept>

namespace farlio {

std::vector<ConfigField> config_fields(Config& c) {
  return {
      {"preprocess.min_range_m", &c.preprocess.min_range_m, "points closer to the sensor are dropped"},
      {"preprocess.max_range_m", &c.preprocess.max_range_m, "points farther from the sensor are dropped"},
      {"map.voxel_size_m", &c.map.voxel_size_m, "edge of a voxel of the submap (paper: 4 m)"},
      {"map.max_points_per_voxel", &c.map.max_points_per_voxel,
       "N_max; the point spacing is voxel_size_m / sqrt(N_max) (paper: 40)"},
      {"map.covariance_neighbors", &c.map.covariance_neighbors, "k nearest neighbours of a covariance (paper: 10)"},
      {"map.covariance_epsilon", &c.map.covariance_epsilon, "eps of the Frobenius regularisation, eq. (1)"},
      {"map.removal_radius_m", &c.map.removal_radius_m, "voxels farther than this from the pose are removed"},
      {"map.refresh_covariances", &c.map.refresh_covariances,
       "recompute covariances of existing points in voxels that receive new points"},
      {"map.initial_voxel_capacity", &c.map.initial_voxel_capacity, "voxels preallocated (grows by doubling)"},
      {"map.max_voxel_capacity", &c.map.max_voxel_capacity, "hard limit of the submap in voxels"},
      {"density.enabled", &c.density.enabled, "adaptive submap density (ASMD)"},
      {"density.close_range_m", &c.density.close_range_m, "range over which the scan's density is averaged"},
      {"density.slope_points_per_m", &c.density.slope_points_per_m, "linear decay of the per-voxel limit with range"},
      {"density.frame_map_max_points_per_voxel", &c.density.frame_map_max_points_per_voxel,
       "cap of the per-scan frame map (source covariances)"},
      {"threshold.initial_threshold_m", &c.threshold.initial_threshold_m, "sigma before any deviation is observed"},
      {"threshold.min_motion_m", &c.threshold.min_motion_m, "model deviations below this are not sampled"},
      {"threshold.max_range_m", &c.threshold.max_range_m, "range that turns a rotation into a displacement"},
      {"threshold.max_threshold_m", &c.threshold.max_threshold_m, "cap of sigma"},
      {"registration.sparsity_aware", &c.registration.sparsity_aware, "GICP with point-to-point fallback"},
      {"registration.max_iterations", &c.registration.max_iterations, "Gauss-Newton iterations at most"},
      {"registration.convergence_norm", &c.registration.convergence_norm, "stop when |dx| falls below this"},
      {"registration.time_budget_factor", &c.registration.time_budget_factor, "time budget in LiDAR periods"},
      {"registration.damping", &c.registration.damping, "lambda added to the diagonal of H"},
      {"num_threads", &c.num_threads, "CPU threads of this pipeline (0: all)"},
  };
}

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

ConfigField find_field(Config& c, const std::string& name) {
  auto fields = config_fields(c);
  for (auto& f : fields) {
    if (f.name == name) return f;
  }
  std::sort(fields.begin(), fields.end(), [&](const ConfigField& a, const ConfigField& b) {
    return edit_distance(a.name, name) < edit_distance(b.name, name);
  });
  constexpr std::size_t kSuggestions = 3;
  std::string msg = "unknown config field '" + name + "'; closest:";
  for (std::size_t i = 0; i < std::min(kSuggestions, fields.size()); ++i) msg += " " + fields[i].name;
  throw std::invalid_argument(msg);
}

template <typename T>
T parse_number(const std::string& name, const std::string& text) {
  T v{};
  const auto* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr != end) {
    throw std::invalid_argument("config field '" + name + "': cannot read '" + text + "' as a number");
  }
  return v;
}

}  // namespace

void set_config_field(Config& config, const std::string& name, const std::string& value) {
  const ConfigField f = find_field(config, name);
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (value == "true" || value == "True" || value == "1") *p = true;
          else if (value == "false" || value == "False" || value == "0") *p = false;
          else throw std::invalid_argument("config field '" + name + "': expected true or false, got '" + value + "'");
        } else {
          *p = parse_number<T>(name, value);
        }
      },
      f.value);
}

std::string get_config_field(const Config& config, const std::string& name) {
  Config copy = config;
  const ConfigField f = find_field(copy, name);
  std::ostringstream os;
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          os << (*p ? "true" : "false");
        } else {
          char buf[64];  // shortest text that reads back to the same value
          const auto r = std::to_chars(buf, buf + sizeof(buf), *p);
          os << std::string_view(buf, static_cast<std::size_t>(r.ptr - buf));
        }
      },
      f.value);
  return os.str();
}

}  // namespace farlio
