#include "farlio/deskew/motion_fit.hpp"

namespace farlio::deskew {

ScanMotion fit_scan_motion(const std::vector<std::pair<double, SE3>>& samples, const SE3& end_pose) {
  const auto n = static_cast<double>(samples.size());
  if (samples.size() < 2) return {};
  const SE3 end_inv = end_pose.inverse();
  double st = 0, stt = 0;
  Vec6d sx = Vec6d::Zero(), stx = Vec6d::Zero();
  for (const auto& [tau, pose] : samples) {
    const Vec6d xi = (end_inv * pose).log();
    st += tau;
    stt += tau * tau;
    sx += xi;
    stx += tau * xi;
  }
  const double det = n * stt - st * st;
  if (det <= 0.0) return {};
  const Vec6d rate = (n * stx - st * sx) / det;
  const Vec6d offset = (sx - rate * st) / n;
  return {offset.cast<float>(), rate.cast<float>()};
}

}  // namespace farlio::deskew
