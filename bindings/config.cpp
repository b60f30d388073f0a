// Bindings of the parameter set (farlio._core.Config): fields by dotted name, typed values.
#include "farlio/core/config.hpp"

#include <nanobind/eigen/dense.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include "bindings.hpp"
#include "farlio/core/config_fields.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

/// A config value as a Python object (the device as its name).
nb::object to_python(const ConfigValue& value) {
  return std::visit(
      [](auto v) -> nb::object {
        if constexpr (std::is_same_v<decltype(v), Device>) {
          return nb::str(device_name(v));
        } else {
          return nb::cast(v);
        }
      },
      value);
}

/// The text form set_config_field parses: bools as true/false, anything else as str() gives it
/// (Python's float text reads back to the same double).
std::string text_of(nb::handle value) {
  if (nb::isinstance<nb::bool_>(value)) return nb::cast<bool>(value) ? "true" : "false";
  return nb::cast<std::string>(nb::str(value));
}

}  // namespace

/// Config: the one parameter set.
void bind_config(nb::module_& m) {
  nb::class_<Config>(m, "Config",
                     "The one parameter set; fields by dotted name, e.g. 'map.voxel_size_m', with their types.")
      .def(nb::init<>())
      .def(nb::init<const Config&>(), "other"_a, "A copy of other.")
      .def(
          "set",
          [](Config& c, const std::string& name, nb::handle value) { set_config_field(c, name, text_of(value)); },
          "name"_a, "value"_a,
          "Sets a field from a number, bool or text; ValueError naming the field if it is unknown or out of range.")
      .def(
          "get", [](const Config& c, const std::string& name) { return to_python(get_config_value(c, name)); },
          "name"_a, "A field's value: float, int, bool, or the device name.")
      .def(
          "validate", [](const Config& c) { validate_config(c); },
          "Raises ValueError naming a field out of its range or a rule that fails.")
      .def_static(
          "fields",
          [] {
            Config c;
            nb::list out;
            for (const auto& f : config_fields(c)) {
              out.append(nb::make_tuple(f.name, to_python(get_config_value(c, f.name)), f.doc,
                                        f.valid.checked ? f.valid.describe() : std::string()));
            }
            return out;
          },
          "[(name, default, doc, valid range)] of every field, in the order of config.hpp.")
      .def(
          "to_dict",
          [](const Config& c) {
            nb::dict d;
            Config copy = c;
            for (const auto& f : config_fields(copy)) d[f.name.c_str()] = to_python(get_config_value(c, f.name));
            return d;
          },
          "{dotted name: typed value} of every field.")
      .def("__eq__",
           [](const Config& a, const Config& b) {
             Config copy = a;
             for (const auto& f : config_fields(copy)) {
               if (get_config_field(a, f.name) != get_config_field(b, f.name)) return false;
             }
             return true;
           })
      .def("__repr__", [](const Config& c) {
        // the fields that differ from the defaults
        const Config defaults;
        Config copy = c;
        std::string changed;
        for (const auto& f : config_fields(copy)) {
          const std::string value = get_config_field(c, f.name);
          if (value == get_config_field(defaults, f.name)) continue;
          changed += (changed.empty() ? "" : ", ") + f.name + "=" + value;
        }
        return "Config(" + (changed.empty() ? std::string("defaults") : changed) + ")";
      });
}

}  // namespace farlio::python
