#pragma once
// Summary statistics of a list of non-negative error magnitudes (metres, degrees, ...).
#include <cstddef>
#include <span>

namespace farlio::eval {

/// Statistics of an error list; every field is 0 for an empty list (check `count`).
struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0.0;  ///< sqrt(mean(e^2))
  double mean = 0.0;
  double median = 0.0;  ///< middle value, or the mean of the two middle values for an even count
  double max = 0.0;
};

ErrorStats compute_stats(std::span<const double> errors);

}  // namespace farlio::eval
