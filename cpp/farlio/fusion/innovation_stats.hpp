#pragma once
// The consistency of the filter with its sensors, from the LiDAR updates' innovations: the
// normalised innovation squared NIS = r' S^-1 r of a measurement group (r its residual against the
// prediction, S = H P H' + R) is chi-squared with dim degrees of freedom when the filter's noise
// (the IMU's input noise, the registration's covariance) fits the data. Its mean per degree of
// freedom is then 1 and 5 % of the groups lie beyond the 95 % quantile; a mean well above 1 says
// the filter trusts its prediction or the LiDAR more than the data allow, well below 1 that it
// trusts them less (Bar-Shalom, Li, Kirubarajan, "Estimation with Applications to Tracking and
// Navigation", 5.4).
#include <cstdint>
#include <string>

namespace farlio::fusion {

/// The 95 % quantile of the chi-squared distribution with dim degrees of freedom (dim 1-6; 0 else).
[[nodiscard]] constexpr double chi2_95(int dim) {
  constexpr double kQuantiles[] = {0.0, 3.841, 5.991, 7.815, 9.488, 11.070, 12.592};
  return dim >= 1 && dim <= 6 ? kQuantiles[dim] : 0.0;
}

struct InnovationStats {
  std::string group;           ///< the measurement group ("pose", "velocity", ...)
  int dim = 0;                 ///< its degrees of freedom
  std::int64_t count = 0;      ///< groups checked (accepted or gated)
  double nis_sum = 0.0;        ///< sum of their NIS
  std::int64_t beyond_95 = 0;  ///< groups beyond chi2_95(dim)

  void add(double nis) {
    ++count;
    nis_sum += nis;
    if (nis > chi2_95(dim)) ++beyond_95;
  }
  /// Mean NIS per degree of freedom: 1 for a consistent filter (0 before the first group).
  [[nodiscard]] double mean_per_dof() const {
    return count > 0 && dim > 0 ? nis_sum / static_cast<double>(count * dim) : 0.0;
  }
  /// Share of groups beyond the 95 % quantile: 0.05 for a consistent filter.
  [[nodiscard]] double share_beyond_95() const {
    return count > 0 ? static_cast<double>(beyond_95) / static_cast<double>(count) : 0.0;
  }
};

}  // namespace farlio::fusion
