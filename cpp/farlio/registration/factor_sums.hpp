#pragma once
// The sum of GICP factors that the reduction accumulates (in double), shared by the CPU
// executor's deterministic reduce and the CUDA block reduction: the upper triangle of H, b,
// the robust cost and the inlier count of one source point, then their sums.
#include <cstdint>

#include "farlio/exec/hd.hpp"
#include "farlio/registration/gicp_factor.hpp"
#include "farlio/registration/linear_system.hpp"

namespace farlio::registration {

inline constexpr int kHEntries = 21;  // upper triangle of the 6x6 H
inline constexpr int kBEntries = 6;

struct FactorSums {
  // Layout: [0, 21) H, [21, 27) b, 27 cost, 28 inliers.
  static constexpr int kCost = kHEntries + kBEntries;
  static constexpr int kInliers = kCost + 1;
  static constexpr int kSize = kInliers + 1;
  double v[kSize];

  FARLIO_HD static FactorSums zero() {
    FactorSums s;
    for (double& x : s.v) x = 0.0;
    return s;
  }
  FARLIO_HD FactorSums& operator+=(const FactorSums& o) {
    for (int k = 0; k < kSize; ++k) v[k] += o.v[k];
    return *this;
  }
};

/// The combine step of the reductions.
struct AddFactorSums {
  FARLIO_HD FactorSums operator()(FactorSums a, const FactorSums& b) const { return a += b; }
};

/// acc + the factor's terms, added in place (nothing without a correspondence: a term of zeros
/// would leave the sums as they are). The CPU registration adds each point's factor to its task's
/// sums with it (CpuExecutor::accumulate); building a FactorSums per point and adding it would cost
/// 14 % of a Gauss-Newton iteration (BM_GicpIteration/1).
FARLIO_HD inline void add_factor(FactorSums& acc, bool found, const FactorTerms& f) {
  if (!found) return;
  for (int k = 0; k < kHEntries; ++k) acc.v[k] += static_cast<double>(f.H[k]);
  for (int k = 0; k < kBEntries; ++k) acc.v[kHEntries + k] += static_cast<double>(f.b[k]);
  acc.v[FactorSums::kCost] += static_cast<double>(f.cost);
  acc.v[FactorSums::kInliers] += 1.0;
}

/// A factor's terms as sums (zero when `found` is false: no correspondence): one term of a
/// reduction over points (CUDA).
FARLIO_HD inline FactorSums factor_sums_of(bool found, const FactorTerms& f) {
  FactorSums a = FactorSums::zero();
  add_factor(a, found, f);
  return a;
}

/// The factor of source point i as sums (zero when it has no correspondence).
FARLIO_HD inline FactorSums factor_sums(const map::ConstMapView& target, const Eigen::Vector4f& point,
                                        const map::Cov3& cov, const FactorParams& fp) {
  FactorTerms f;
  const bool found = gicp_factor(target, point, cov, fp, f);
  return factor_sums_of(found, f);
}

/// The symmetric linear system of the sums (host).
inline LinearSystem to_linear_system(const FactorSums& a) {
  LinearSystem s;
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) {
      s.H(i, j) = a.v[k];
      s.H(j, i) = a.v[k];
      ++k;
    }
    s.b(i) = a.v[kHEntries + i];
  }
  s.error = a.v[FactorSums::kCost];
  s.inliers = static_cast<long>(a.v[FactorSums::kInliers]);
  return s;
}

}  // namespace farlio::registration
