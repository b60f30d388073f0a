#pragma once
// The range crop of a scan point, a kernel body shared by the CPU preprocessing and the CUDA
// backend: a point is kept when it is finite and its range lies in [min_range_m, max_range_m].
#include <Eigen/Core>

#include "farlio/core/config.hpp"
#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"

namespace farlio::preprocess {

struct RangeCrop {
  float min_range2 = 0.0f;
  float max_range2 = 0.0f;

  static RangeCrop from(const PreprocessConfig& c) {
    return {static_cast<float>(c.min_range_m * c.min_range_m), static_cast<float>(c.max_range_m * c.max_range_m)};
  }
  FARLIO_HD bool keeps(const Eigen::Vector3f& p) const {
    const float r2 = p.squaredNorm();
    return exec::is_finite(r2) && r2 >= min_range2 && r2 <= max_range2;
  }
};

}  // namespace farlio::preprocess
