#pragma once
// __repr__ texts of the bound classes, one format for all: "Type(name=value, ...)", numbers to
// kReprDigits significant digits, bools as True/False, text quoted, vectors as [x, y, z],
// poses as SE3(t=[x, y, z], rpy_deg=[roll, pitch, yaw]), optional values as None when empty.
// Most classes list the attributes to show (attribute_repr); a few build their text (Repr).
#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio::python {

/// Significant digits of the floating-point numbers in a repr.
inline constexpr int kReprDigits = 6;
inline constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

/// Roll, pitch and yaw in degrees of R = Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Vector3d rpy_deg(const Mat3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))) * kDegreesPerRadian;
}

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

/// The repr text of one value (see the file comment); maps as {key: value}, ranges as [a, b].
template <class T>
std::string repr_value(const T& v) {
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "True" : "False";
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else if constexpr (std::is_floating_point_v<T>) {
    const double x = v == 0 ? 0.0 : static_cast<double>(v);  // no "-0"
    std::array<char, 32> text{};
    const auto end =
        std::to_chars(text.data(), text.data() + text.size(), x, std::chars_format::general, kReprDigits).ptr;
    return {text.data(), end};
  } else if constexpr (std::is_convertible_v<T, std::string_view>) {
    return "'" + std::string(std::string_view(v)) + "'";
  } else if constexpr (std::is_same_v<T, SE3>) {
    return "SE3(t=" + repr_value(v.translation()) + ", rpy_deg=" + repr_value(rpy_deg(v.rotation())) + ")";
  } else if constexpr (IsOptional<T>::value) {
    return v ? repr_value(*v) : "None";
  } else if constexpr (std::is_base_of_v<Eigen::DenseBase<T>, T>) {
    return repr_value(std::vector<double>(v.data(), v.data() + v.size()));
  } else if constexpr (requires { typename T::mapped_type; }) {
    std::string text;
    for (const auto& [key, value] : v) text += (text.empty() ? "" : ", ") + repr_value(key) + ": " + repr_value(value);
    return "{" + text + "}";
  } else {
    std::string text;
    for (const auto& item : v) text += (text.empty() ? "" : ", ") + repr_value(item);
    return "[" + text + "]";
  }
}

/// Builds "Type(item, name=value, ...)".
class Repr {
 public:
  explicit Repr(std::string_view type) : text_(type) { text_ += '('; }
  /// A positional item, written as given (e.g. "30 poses").
  Repr& item(std::string_view text) {
    if (!first_) text_ += ", ";
    text_ += text;
    first_ = false;
    return *this;
  }
  /// name=<already formatted text>, e.g. the repr of a nested result.
  Repr& raw(std::string_view name, std::string_view text) { return item(std::string(name) + "=" + std::string(text)); }
  template <class T>
  Repr& field(std::string_view name, const T& value) {
    return raw(name, repr_value(value));
  }
  [[nodiscard]] std::string str() const { return text_ + ")"; }

 private:
  std::string text_;
  bool first_ = true;
};

/// The repr text of a Python value: numbers and numpy arrays as repr_value writes them, bound
/// objects by their own __repr__, anything else by Python's repr.
inline std::string python_value_repr(nanobind::handle v) {
  namespace nb = nanobind;
  if (nb::isinstance<nb::bool_>(v)) return repr_value(nb::cast<bool>(v));  // before int: a bool is an int
  if (nb::isinstance<nb::float_>(v)) return repr_value(nb::cast<double>(v));
  if (nb::hasattr(v, "tolist")) return python_value_repr(v.attr("tolist")());  // numpy arrays
  if (nb::isinstance<nb::list>(v) || nb::isinstance<nb::tuple>(v)) {
    std::string text;
    for (nb::handle item : v) text += (text.empty() ? "" : ", ") + python_value_repr(item);
    return "[" + text + "]";
  }
  return nb::cast<std::string>(nb::repr(v));
}

/// A __repr__ showing the named attributes of a bound object: "Type(name=value, ...)".
inline auto attribute_repr(std::vector<const char*> names) {
  return [names = std::move(names)](nanobind::handle self) {
    Repr r(nanobind::cast<std::string>(self.type().attr("__name__")));
    for (const char* name : names) r.raw(name, python_value_repr(self.attr(name)));
    return r.str();
  };
}

}  // namespace farlio::python
