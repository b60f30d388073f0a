#pragma once
// Every field of Config by its dotted name (e.g. "map.voxel_size_m"), with its documentation:
// the one place through which YAML files, command-line overrides and the written effective
// config reach the parameter set.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "farlio/core/config.hpp"

namespace farlio {

struct ConfigField {
  std::string name;
  std::variant<double*, int*, std::int64_t*, bool*, Device*> value;
  std::string doc;
};

/// The fields of `config` (pointers into it).
std::vector<ConfigField> config_fields(Config& config);

/// Sets a field from its text form; throws std::invalid_argument naming the field (and the
/// closest known names) when it is unknown or the value does not parse.
void set_config_field(Config& config, const std::string& name, const std::string& value);

/// The field's value as text.
std::string get_config_field(const Config& config, const std::string& name);

}  // namespace farlio
