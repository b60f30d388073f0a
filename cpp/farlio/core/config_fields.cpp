#include "farlio/core/config_fields.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace farlio {
namespace {

// One entry per field of a section's list in config.hpp; `section` and `prefix` are the
// parameters of the function the list expands in.
#define FARLIO_FIELD_ENTRY(type, name, default_value, valid, doc) \
  out.push_back(ConfigField{prefix + #name, &section.name, doc, valid});
#define FARLIO_SECTION_FIELDS(Section, LIST)                                                       \
  void append_fields(std::vector<ConfigField>& out, Section& section, const std::string& prefix) { \
    LIST(FARLIO_FIELD_ENTRY)                                                                       \
  }

FARLIO_SECTION_FIELDS(PreprocessConfig, FARLIO_PREPROCESS_FIELDS)
FARLIO_SECTION_FIELDS(VoxelMapConfig, FARLIO_MAP_FIELDS)
FARLIO_SECTION_FIELDS(AdaptiveDensityConfig, FARLIO_DENSITY_FIELDS)
FARLIO_SECTION_FIELDS(ThresholdConfig, FARLIO_THRESHOLD_FIELDS)
FARLIO_SECTION_FIELDS(RegistrationConfig, FARLIO_REGISTRATION_FIELDS)
FARLIO_SECTION_FIELDS(FusionInitConfig, FARLIO_FUSION_INIT_FIELDS)
FARLIO_SECTION_FIELDS(FusionBiasConfig, FARLIO_FUSION_BIAS_FIELDS)
FARLIO_SECTION_FIELDS(FusionImuGateConfig, FARLIO_FUSION_IMU_GATE_FIELDS)
FARLIO_SECTION_FIELDS(FusionReferenceAnglesConfig, FARLIO_FUSION_REFERENCE_ANGLES_FIELDS)
FARLIO_SECTION_FIELDS(FusionDelayConfig, FARLIO_FUSION_DELAY_FIELDS)
FARLIO_SECTION_FIELDS(FusionStandstillConfig, FARLIO_FUSION_STANDSTILL_FIELDS)
FARLIO_SECTION_FIELDS(FusionUnitsConfig, FARLIO_FUSION_UNITS_FIELDS)
FARLIO_SECTION_FIELDS(LocalizationConfig, FARLIO_LOCALIZATION_FIELDS)
FARLIO_SECTION_FIELDS(LoopClosureConfig, FARLIO_LOOP_FIELDS)
FARLIO_SECTION_FIELDS(CudaConfig, FARLIO_CUDA_FIELDS)
FARLIO_SECTION_FIELDS(Config, FARLIO_TOP_FIELDS)

/// The filter's own fields, then those of its parts one level deeper ("fusion.init.window_s").
void append_fields(std::vector<ConfigField>& out, FusionConfig& section, const std::string& prefix) {
  FARLIO_FUSION_FIELDS(FARLIO_FIELD_ENTRY)
  append_fields(out, section.init, prefix + "init.");
  append_fields(out, section.bias, prefix + "bias.");
  append_fields(out, section.imu_gate, prefix + "imu_gate.");
  append_fields(out, section.reference_angles, prefix + "reference_angles.");
  append_fields(out, section.delay, prefix + "delay.");
  append_fields(out, section.standstill, prefix + "standstill.");
  append_fields(out, section.units, prefix + "units.");
}

#undef FARLIO_SECTION_FIELDS
#undef FARLIO_FIELD_ENTRY

/// Fields that moved into a sub-section: an old name is unknown, and its error names the new one.
const std::vector<std::pair<std::string_view, std::string_view>> kRenamedFields = {
    {"fusion.initial_position_std_m", "fusion.init.position_std_m"},
    {"fusion.initial_attitude_std_rad", "fusion.init.attitude_std_rad"},
    {"fusion.init_window_s", "fusion.init.window_s"},
    {"fusion.estimate_imu_bias", "fusion.bias.estimate"},
    {"fusion.gyro_bias_std_rad_s", "fusion.bias.gyro_std_rad_s"},
    {"fusion.accel_bias_std_m_s2", "fusion.bias.accel_std_m_s2"},
    {"fusion.gyro_bias_walk_rad_s2_sqrt_hz", "fusion.bias.gyro_walk_rad_s2_sqrt_hz"},
    {"fusion.accel_bias_walk_m_s3_sqrt_hz", "fusion.bias.accel_walk_m_s3_sqrt_hz"},
    {"fusion.gyro_bias_init_x_rad_s", "fusion.bias.gyro_init_x_rad_s"},
    {"fusion.gyro_bias_init_y_rad_s", "fusion.bias.gyro_init_y_rad_s"},
    {"fusion.gyro_bias_init_z_rad_s", "fusion.bias.gyro_init_z_rad_s"},
    {"fusion.accel_bias_x_m_s2", "fusion.bias.accel_init_x_m_s2"},
    {"fusion.accel_bias_y_m_s2", "fusion.bias.accel_init_y_m_s2"},
    {"fusion.accel_bias_z_m_s2", "fusion.bias.accel_init_z_m_s2"},
    {"fusion.imu_gap_limit_s", "fusion.imu_gate.gap_limit_s"},
    {"fusion.max_bridged_gap_s", "fusion.imu_gate.max_bridged_gap_s"},
    {"fusion.imu_max_accel_m_s2", "fusion.imu_gate.max_accel_m_s2"},
    {"fusion.imu_max_gyro_rad_s", "fusion.imu_gate.max_gyro_rad_s"},
    {"fusion.imu_spike_accel_m_s2", "fusion.imu_gate.spike_accel_m_s2"},
    {"fusion.imu_spike_gyro_rad_s", "fusion.imu_gate.spike_gyro_rad_s"},
    {"fusion.imu_spike_window_samples", "fusion.imu_gate.spike_window_samples"},
    {"fusion.reference_angles", "fusion.reference_angles.enabled"},
    {"fusion.reference_roll_std_rad", "fusion.reference_angles.roll_std_rad"},
    {"fusion.reference_pitch_std_rad", "fusion.reference_angles.pitch_std_rad"},
    {"fusion.reference_filter_taps", "fusion.reference_angles.filter_taps"},
    {"fusion.reference_max_sin", "fusion.reference_angles.max_sin"},
    {"fusion.delay_compensation", "fusion.delay.compensation"},
    {"fusion.update_spread_steps", "fusion.delay.spread_steps"},
    {"fusion.max_update_spread_steps", "fusion.delay.max_spread_steps"},
    {"fusion.standstill_bias", "fusion.standstill.gyro_bias"},
    {"fusion.standstill_max_speed_m_s", "fusion.standstill.max_speed_m_s"},
    {"fusion.standstill_max_gyro_rad_s", "fusion.standstill.max_gyro_rad_s"},
    {"fusion.standstill_max_accel_deviation_m_s2", "fusion.standstill.max_accel_deviation_m_s2"},
    {"fusion.bias_window_samples", "fusion.standstill.window_samples"},
    {"fusion.bias_prior_samples", "fusion.standstill.prior_samples"},
    {"fusion.accel_unit_detection", "fusion.units.accel_detection"},
    {"fusion.accel_unit_detection_samples", "fusion.units.accel_samples"},
    {"fusion.gyro_unit_detection", "fusion.units.gyro_detection"},
    {"fusion.gyro_unit_min_rotation_rad", "fusion.units.gyro_min_rotation_rad"},
};

/// " (renamed to NEW)" when `name` is the old name of a field, else "".
std::string renamed_note(const std::string& name) {
  for (const auto& [old_name, new_name] : kRenamedFields) {
    if (old_name == name) return " (renamed to " + std::string(new_name) + ")";
  }
  return "";
}

/// The fields of one section, named under `prefix` ("map" gives "map.voxel_size_m").
template <typename Section>
std::vector<ConfigField> section_fields(Section& section, const std::string& prefix) {
  std::vector<ConfigField> out;
  append_fields(out, section, prefix + ".");
  return out;
}

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
  std::string msg = "unknown config field '" + name + "'" + renamed_note(name) + "; closest:";
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

/// Shortest text that reads back to the same number ("inf", "nan" for those).
template <typename T>
std::string number_text(T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

bool parse_bool(const std::string& name, const std::string& text) {
  if (text == "true" || text == "True" || text == "1") return true;
  if (text == "false" || text == "False" || text == "0") return false;
  throw std::invalid_argument("config field '" + name + "': expected true or false, got '" + text + "'");
}

/// Throws naming the field when its value lies outside its range.
void check_range(const ConfigField& f) {
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (!std::is_same_v<T, bool> && !std::is_same_v<T, Device>) {
          if (!f.valid.contains(static_cast<double>(*p))) {
            throw std::invalid_argument("config field '" + f.name + "' must be " + f.valid.describe() + ", got " +
                                        number_text(*p));
          }
        }
      },
      f.value);
}

void require(bool holds, const std::string& rule) {
  if (!holds) throw std::invalid_argument("config: " + rule);
}

template <typename Section>
void check_ranges(const Section& section, const std::string& prefix) {
  Section copy = section;
  for (const ConfigField& f : section_fields(copy, prefix)) check_range(f);
}

}  // namespace

const std::vector<std::pair<std::string_view, std::string_view>>& renamed_config_fields() { return kRenamedFields; }

bool FieldRange::contains(double v) const {
  if (!checked) return true;
  if (std::isnan(v)) return false;
  if (std::isinf(v)) return v > 0 && allow_infinity;
  return (min_exclusive ? v > min : v >= min) && v <= max;
}

std::string FieldRange::describe() const {
  std::string s;
  if (std::isinf(min) && std::isinf(max)) {
    s = "finite";
  } else if (std::isinf(max)) {
    s = (min_exclusive ? "> " : ">= ") + number_text(min);
  } else if (std::isinf(min)) {
    s = "<= " + number_text(max);
  } else {
    s = "in " + std::string(min_exclusive ? "(" : "[") + number_text(min) + ", " + number_text(max) + "]";
  }
  return allow_infinity ? s + " or inf" : s;
}

std::vector<ConfigField> config_fields(Config& c) {
  std::vector<ConfigField> out;
  append_fields(out, c.preprocess, "preprocess.");
  append_fields(out, c.map, "map.");
  append_fields(out, c.density, "density.");
  append_fields(out, c.threshold, "threshold.");
  append_fields(out, c.registration, "registration.");
  append_fields(out, c.fusion, "fusion.");
  append_fields(out, c.localization, "localization.");
  append_fields(out, c.loop, "loop.");
  append_fields(out, c.cuda, "cuda.");
  append_fields(out, c, "");
  return out;
}

void set_config_field(Config& config, const std::string& name, const std::string& value) {
  Config candidate = config;  // the config only changes when the new value is valid
  const ConfigField target = find_field(candidate, name);
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, Device>) {
          *p = parse_device(value, "config field '" + name + "'");
        } else if constexpr (std::is_same_v<T, bool>) {
          *p = parse_bool(name, value);
        } else {
          *p = parse_number<T>(name, value);
        }
      },
      target.value);
  check_range(target);
  config = candidate;
}

ConfigValue get_config_value(const Config& config, const std::string& name) {
  Config copy = config;
  const ConfigField f = find_field(copy, name);
  return std::visit([](auto* p) { return ConfigValue(*p); }, f.value);
}

std::string get_config_field(const Config& config, const std::string& name) {
  return std::visit(
      [](auto v) -> std::string {
        using T = decltype(v);
        if constexpr (std::is_same_v<T, Device>) {
          return device_name(v);
        } else if constexpr (std::is_same_v<T, bool>) {
          return v ? "true" : "false";
        } else {
          return number_text(v);
        }
      },
      get_config_value(config, name));
}

void validate_config(const VoxelMapConfig& map, const std::string& prefix) {
  check_ranges(map, prefix);
  require(!map.auto_voxel_size || map.auto_min_voxel_size_m <= map.voxel_size_m,
          prefix + ".auto_min_voxel_size_m (" + number_text(map.auto_min_voxel_size_m) + ") must not exceed " + prefix +
              ".voxel_size_m (" + number_text(map.voxel_size_m) + ", the largest auto voxel)");
  require(map.initial_voxel_capacity <= map.max_voxel_capacity,
          prefix + ".initial_voxel_capacity (" + number_text(map.initial_voxel_capacity) + ") must not exceed " +
              prefix + ".max_voxel_capacity (" + number_text(map.max_voxel_capacity) + ")");
}

void validate_config(const FusionConfig& fusion) {
  check_ranges(fusion, "fusion");
  require(fusion.reference_angles.filter_taps % 2 == 1,
          "fusion.reference_angles.filter_taps must be odd, got " + number_text(fusion.reference_angles.filter_taps));
  require(fusion.history_s >= fusion.step_s, "fusion.history_s (" + number_text(fusion.history_s) +
                                                 ") must hold at least one fusion.step_s (" +
                                                 number_text(fusion.step_s) + ")");
  require(fusion.imu_gate.gap_limit_s <= fusion.imu_gate.max_bridged_gap_s,
          "fusion.imu_gate.gap_limit_s (" + number_text(fusion.imu_gate.gap_limit_s) +
              ") must not exceed fusion.imu_gate.max_bridged_gap_s (" + number_text(fusion.imu_gate.max_bridged_gap_s) +
              "): a gap the fusion holds its input across must be bridged");
  require(fusion.init.window_s < fusion.history_s,
          "fusion.init.window_s (" + number_text(fusion.init.window_s) + ") must be below fusion.history_s (" +
              number_text(fusion.history_s) + "): the initialisation reads the IMU of its window from that history");
}

void validate_config(const Config& config) {
  check_ranges(config.preprocess, "preprocess");
  require(config.preprocess.min_range_m < config.preprocess.max_range_m,
          "preprocess.min_range_m (" + number_text(config.preprocess.min_range_m) +
              ") must be below preprocess.max_range_m (" + number_text(config.preprocess.max_range_m) + ")");
  validate_config(config.map);
  check_ranges(config.density, "density");
  check_ranges(config.threshold, "threshold");
  check_ranges(config.registration, "registration");
  validate_config(config.fusion);
  check_ranges(config.localization, "localization");
  check_ranges(config.loop, "loop");
  check_ranges(config.cuda, "cuda");
  Config copy = config;
  std::vector<ConfigField> top;
  append_fields(top, copy, "");
  for (const ConfigField& f : top) check_range(f);
}

void validate_gravity(double gravity_m_s2, const std::string& source) {
  if (gravity_m_s2 >= kMinGravity_m_s2 && gravity_m_s2 <= kMaxGravity_m_s2) return;  // false for NaN
  throw std::invalid_argument(source + ": must be the magnitude of gravity in m/s^2, about 9.8 (in [" +
                              number_text(kMinGravity_m_s2) + ", " + number_text(kMaxGravity_m_s2) + "]), got " +
                              number_text(gravity_m_s2) +
                              (gravity_m_s2 < 0.0 ? " (no sign: the direction comes from the accelerometer)" : ""));
}

}  // namespace farlio
