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
// Every numeric field has a finite upper bound (or allows inf explicitly as "no limit"): a value
// beyond what any sensor or computer needs is a typo, and some would overflow a conversion (s to
// ns) or an allocation (history entries, filter taps).
/// bool and enum fields.
constexpr FieldRange unchecked() { return {-kInf, kInf, false, false, false}; }
/// lo <= v <= hi.
constexpr FieldRange between(double lo, double hi) { return {lo, hi, false, false, true}; }
/// 0 < v <= hi.
constexpr FieldRange positive_up_to(double hi) { return {0.0, hi, true, false, true}; }
/// 0 < v <= hi, or inf for "no limit".
constexpr FieldRange positive_up_to_or_inf(double hi) { return {0.0, hi, true, true, true}; }
/// 0 <= v <= hi.
constexpr FieldRange non_negative_up_to(double hi) { return {0.0, hi, false, false, true}; }
/// -limit <= v <= limit.
constexpr FieldRange symmetric(double limit) { return {-limit, limit, false, false, true}; }
/// 0 < v <= 1.
constexpr FieldRange fraction() { return {0.0, 1.0, true, false, true}; }
}  // namespace range

}  // namespace farlio
