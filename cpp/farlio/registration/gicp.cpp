#include "farlio/registration/gicp.hpp"

#include <Eigen/Cholesky>
#include <chrono>

#include "farlio/registration/factor_sums.hpp"

namespace farlio::registration {

SourceCloud source_from_map(const map::MapView& m, std::size_t voxel_capacity) {
  SourceCloud src;
  for (std::size_t v = 0; v < voxel_capacity; ++v) {
    const auto vox = static_cast<std::int32_t>(v);
    for (std::int32_t j = 0; j < m.voxel_counts[v]; ++j) {
      src.points.push_back(m.points[m.point_index(vox, j)]);
      src.covs.push_back(m.covs[m.point_index(vox, j)]);
    }
  }
  return src;
}

FactorParams factor_params(const SE3& T, const Thresholds& th, bool sparsity_aware) {
  FactorParams fp;
  fp.R = T.rotation().cast<float>();
  fp.t = T.translation().cast<float>();
  fp.max_correspondence_distance2 = static_cast<float>(th.max_correspondence_m * th.max_correspondence_m);
  fp.kernel.kappa_m = static_cast<float>(th.kernel_scale_m);
  fp.sparsity_aware = sparsity_aware;
  return fp;
}

LinearSystem build_linear_system(const SourceCloud& source, const map::MapView& target, const SE3& T,
                                 const Thresholds& th, bool sparsity_aware, exec::CpuExecutor& executor) {
  const FactorParams fp = factor_params(T, th, sparsity_aware);
  const FactorSums sum = executor.reduce(
      source.size(), FactorSums::zero(),
      [&](std::size_t i) { return factor_sums(target, source.points[i], source.covs[i], fp); }, AddFactorSums{});
  return to_linear_system(sum);
}

RegistrationResult register_scan(const SourceCloud& source, const map::MapView& target, const SE3& initial_guess,
                                 const Thresholds& th, const RegistrationConfig& config, double time_budget_s,
                                 exec::CpuExecutor& executor) {
  return gauss_newton(
      [&](const SE3& T) { return build_linear_system(source, target, T, th, config.sparsity_aware, executor); },
      initial_guess, config, time_budget_s);
}

RegistrationResult gauss_newton(const SystemBuilder& build, const SE3& initial_guess, const RegistrationConfig& config,
                                double time_budget_s) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed_s = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  RegistrationResult res;
  res.pose = initial_guess;
  for (int it = 0; it < config.max_iterations; ++it) {
    res.system = build(res.pose);
    res.iterations = it + 1;
    if (res.system.inliers == 0) break;  // nothing to register against: not converged
    const Mat6d H = res.system.H + config.damping * Mat6d::Identity();
    const Vec6d dx = H.ldlt().solve(-res.system.b);
    if (!dx.allFinite()) break;
    res.pose = res.pose * SE3::exp(dx);
    if (dx.norm() < config.convergence_norm) {
      res.converged = true;
      break;
    }
    if (elapsed_s() >= time_budget_s) {
      res.budget_exceeded = true;
      break;
    }
  }
  res.time_s = elapsed_s();
  return res;
}

}  // namespace farlio::registration
