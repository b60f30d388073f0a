#pragma once
// Small math helpers that Eigen 3.4 offers on the host only (allFinite is not a device
// function), written once for the shared kernel bodies.
#include <cmath>

#include "farlio/exec/hd.hpp"

namespace farlio::exec {

FARLIO_HD inline bool is_finite(float x) {
#ifdef FARLIO_ON_DEVICE
  return isfinite(x);
#else
  return std::isfinite(x);
#endif
}

/// True if every coefficient of a fixed-size float matrix or vector is finite.
template <typename Derived>
FARLIO_HD bool all_finite(const Derived& m) {
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) {
      if (!is_finite(m(r, c))) return false;
    }
  }
  return true;
}

}  // namespace farlio::exec
