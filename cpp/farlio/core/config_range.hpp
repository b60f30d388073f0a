#pragma once
// The valid values of a numeric config field: a lower and an upper bound, each inclusive or not,
// and whether +infinity is allowed (it then means "no limit"). NaN is never valid. config.hpp
// gives every field one; set_config_field and validate_config enforce them.
#include <limits>
#include <string>

namespace farlio {

struct FieldRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  bool allow_infinity = false;  ///< +inf is valid (a limit switched off)
  bool checked = true;          ///< false: not a number (bool, device), nothing to check

  [[nodiscard]] bool contains(double v) const;
  /// "> 0", ">= 1", "in [1, 32]", "> 0 or inf", ...
  [[nodiscard]] std::string describe() const;
};

namespace range {
inline constexpr double kInf = std::numeric_limits<double>::infinity();
/// bool and enum fields.
constexpr FieldRange unchecked() { return {-kInf, kInf, false, false, false}; }
/// Any finite number.
constexpr FieldRange finite() { return {-kInf, kInf, false, false, true}; }
constexpr FieldRange positive() { return {0.0, kInf, true, false, true}; }
/// Positive, or inf for "no limit".
constexpr FieldRange positive_or_inf() { return {0.0, kInf, true, true, true}; }
constexpr FieldRange non_negative() { return {0.0, kInf, false, false, true}; }
constexpr FieldRange at_least(double lo) { return {lo, kInf, false, false, true}; }
/// lo <= v <= hi.
constexpr FieldRange between(double lo, double hi) { return {lo, hi, false, false, true}; }
/// 0 < v <= 1.
constexpr FieldRange fraction() { return {0.0, 1.0, true, false, true}; }
}  // namespace range

}  // namespace farlio
