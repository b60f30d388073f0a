#include "farlio/deskew/rotation_rate_blend.hpp"

#include <algorithm>
#include <cmath>

#include "farlio/core/time.hpp"

namespace farlio::deskew {

Eigen::Vector3d RotationRateBlend::blend(const Eigen::Vector3d& gyro_rate, const Eigen::Vector3d& twist_rate,
                                         const std::optional<Eigen::Vector3d>& gyro_variance, std::int64_t stamp_ns) {
  const Eigen::Vector3d disagreement = (gyro_rate - twist_rate).cwiseAbs2();
  gyro_weight_.setOnes();
  if (gyro_variance && disagreement_variance_) {
    for (int i = 0; i < 3; ++i) {
      const double total = (*disagreement_variance_)[i];
      if (disagreement[i] > kChangeRatio * kChangeRatio * total) continue;  // a change of motion: the gyro
      const double twist_variance = std::max(0.0, total - (*gyro_variance)[i]);
      const double sum = twist_variance + (*gyro_variance)[i];
      gyro_weight_[i] = sum > 0.0 ? twist_variance / sum : 1.0;
    }
  }
  const double forget = std::clamp(ns_to_seconds(stamp_ns - last_stamp_ns_) / kMemory_s, 0.0, 1.0);
  last_stamp_ns_ = stamp_ns;
  if (disagreement_variance_)
    *disagreement_variance_ += forget * (disagreement - *disagreement_variance_);
  else
    disagreement_variance_ = disagreement;
  return gyro_weight_.cwiseProduct(gyro_rate) + (Eigen::Vector3d::Ones() - gyro_weight_).cwiseProduct(twist_rate);
}

}  // namespace farlio::deskew
