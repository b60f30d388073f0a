#pragma once
// Degree/radian conversion for the evaluation reports.
#include <numbers>

namespace farlio::eval {

inline constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

}  // namespace farlio::eval
