#pragma once
// The per-voxel point limit of the adaptive submap density (ASMD): a function of the distance
// of the inserted point from the sensor. Shared by the CPU and CUDA map updates.
#include "farlio/exec/hd.hpp"

namespace farlio::map {

/// The per-voxel point limit for a point at a given distance from the sensor (ASMD, or a
/// constant). Evaluated per inserted point.
struct PointLimit {
  int close_limit = 40;        ///< limit within close_range_m
  float close_range_m = 0.0f;  ///< beyond it the limit decays linearly
  float slope_per_m = 0.0f;    ///< points per metre of decay
  int min_limit = 40;          ///< floor of the decay (k, so covariances stay computable)

  static PointLimit constant(int n) { return {n, 0.0f, 0.0f, n}; }
  FARLIO_HD int at(float distance_m) const {
    if (distance_m <= close_range_m) return close_limit;
    const float decayed = static_cast<float>(close_limit) - slope_per_m * (distance_m - close_range_m);
    const int lim = static_cast<int>(decayed);
    return lim > min_limit ? lim : min_limit;
  }
};

}  // namespace farlio::map
