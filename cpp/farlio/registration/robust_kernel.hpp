#pragma once
// The Cauchy robust kernel (paper eq. 4): rho(e) = kappa^2 / 2 * log(1 + (e / kappa)^2), used
// by iteratively reweighted least squares with the weight rho'(e) / e = 1 / (1 + (e / kappa)^2).
#include <cmath>

#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"

namespace farlio::registration {

struct CauchyKernel {
  float kappa_m = 1.0f;

  FARLIO_HD float weight(float residual2) const { return 1.0f / (1.0f + residual2 / (kappa_m * kappa_m)); }
  FARLIO_HD float cost(float residual2) const {
    return 0.5f * kappa_m * kappa_m * exec::log1p_nonnegative(residual2 / (kappa_m * kappa_m));
  }
};

}  // namespace farlio::registration
