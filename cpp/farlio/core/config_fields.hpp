#pragma once
// Every field of Config by its dotted name (e.g. "map.voxel_size_m"), with its documentation and
// valid range, generated from the field lists of config.hpp: the one place through which YAML
// files, command-line overrides, the written effective config and the bindings reach the
// parameter set, and where it is validated.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/config_range.hpp"

namespace farlio {

struct ConfigField {
  std::string name;
  std::variant<double*, int*, std::int64_t*, bool*, Device*> value;
  std::string doc;
  FieldRange valid;
};

/// A field's value with its type.
using ConfigValue = std::variant<double, int, std::int64_t, bool, Device>;

/// The fields of `config` (pointers into it), in the order of config.hpp.
std::vector<ConfigField> config_fields(Config& config);

/// {old dotted name, new dotted name} of the fields that moved into a sub-section: an old name is
/// an unknown field whose error names the new one.
const std::vector<std::pair<std::string_view, std::string_view>>& renamed_config_fields();

/// Sets a field from its text form; throws std::invalid_argument naming the field (and the
/// closest known names) when it is unknown, the value does not parse or is out of its range.
void set_config_field(Config& config, const std::string& name, const std::string& value);

/// The field's value as text (numbers in their shortest exact form).
std::string get_config_field(const Config& config, const std::string& name);
/// The field's value with its type.
ConfigValue get_config_value(const Config& config, const std::string& name);

/// Throws std::invalid_argument naming the first field out of its range (NaN included) or the
/// fields of a rule between fields that does not hold (e.g. preprocess.min_range_m below
/// preprocess.max_range_m).
void validate_config(const Config& config);
/// The checks of validate_config that concern one section, naming its fields under `prefix`.
void validate_config(const VoxelMapConfig& map, const std::string& prefix = "map");
void validate_config(const FusionConfig& fusion);

/// Gravity is a magnitude in m/s^2 close to Earth's (9.78 at the equator, 9.83 at the poles): a sign,
/// 0, or 1 (gravity in g) is a mistake.
inline constexpr double kMinGravity_m_s2 = 9.5;
inline constexpr double kMaxGravity_m_s2 = 10.2;
/// Throws std::invalid_argument naming `source` (where the value came from) when gravity_m_s2 is
/// not a magnitude in [kMinGravity_m_s2, kMaxGravity_m_s2].
void validate_gravity(double gravity_m_s2, const std::string& source);

/// `config` (a Config or a section above) after validate_config, for member initialisers.
template <typename C>
const C& validated(const C& config) {
  validate_config(config);
  return config;
}

}  // namespace farlio
