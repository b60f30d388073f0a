#include "farlio/core/config_fields.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>

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
FARLIO_SECTION_FIELDS(FusionConfig, FARLIO_FUSION_FIELDS)
FARLIO_SECTION_FIELDS(LocalizationConfig, FARLIO_LOCALIZATION_FIELDS)
FARLIO_SECTION_FIELDS(LoopClosureConfig, FARLIO_LOOP_FIELDS)
FARLIO_SECTION_FIELDS(CudaConfig, FARLIO_CUDA_FIELDS)
FARLIO_SECTION_FIELDS(Config, FARLIO_TOP_FIELDS)

#undef FARLIO_SECTION_FIELDS
#undef FARLIO_FIELD_ENTRY

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
  require(fusion.reference_filter_taps % 2 == 1,
          "fusion.reference_filter_taps must be odd, got " + number_text(fusion.reference_filter_taps));
  require(fusion.history_s >= fusion.step_s, "fusion.history_s (" + number_text(fusion.history_s) +
                                                 ") must hold at least one fusion.step_s (" +
                                                 number_text(fusion.step_s) + ")");
  require(fusion.imu_gap_limit_s <= fusion.max_bridged_gap_s,
          "fusion.imu_gap_limit_s (" + number_text(fusion.imu_gap_limit_s) +
              ") must not exceed fusion.max_bridged_gap_s (" + number_text(fusion.max_bridged_gap_s) +
              "): a gap the fusion holds its input across must be bridged");
  require(fusion.init_window_s < fusion.history_s,
          "fusion.init_window_s (" + number_text(fusion.init_window_s) + ") must be below fusion.history_s (" +
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
