#pragma once
// The per-axis median of 3-vectors (the upper middle value for an even count): the IMU gate's
// spike test takes it of recent samples, the IMU noise meter of |second differences|.
#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <vector>

namespace farlio::fusion {

/// The median of each axis of value(item) over `items` (an empty range gives zeros).
template <typename Range, typename Value>
Eigen::Vector3d axis_median(const Range& items, Value value) {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  std::vector<double> axis_values;
  axis_values.reserve(static_cast<std::size_t>(std::distance(std::begin(items), std::end(items))));
  for (int axis = 0; axis < 3; ++axis) {
    axis_values.clear();
    for (const auto& item : items) axis_values.push_back(value(item)(axis));
    if (axis_values.empty()) continue;
    const auto mid = axis_values.begin() + static_cast<std::ptrdiff_t>(axis_values.size() / 2);
    std::nth_element(axis_values.begin(), mid, axis_values.end());
    m(axis) = *mid;
  }
  return m;
}

}  // namespace farlio::fusion
