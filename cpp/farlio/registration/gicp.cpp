#include "farlio/registration/gicp.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "farlio/registration/degeneracy.hpp"
#include "farlio/registration/factor_sums.hpp"

namespace farlio::registration {

double point_to_point_precision(const RegistrationConfig& config, double covariance_epsilon, double spacing_m) {
  constexpr double kSigmaPerSpacing = 0.5;  // the matched sample may lie up to half a spacing away
  const double sigma_m =
      config.point_to_point_sigma_m > 0.0 ? config.point_to_point_sigma_m : kSigmaPerSpacing * spacing_m;
  const double sigma2 = sigma_m * sigma_m;
  return sigma2 > 0.0 ? covariance_epsilon / sigma2 : 1.0;
}

void source_from_map(const map::ConstMapView& m, std::size_t voxel_capacity, SourceCloud& source) {
  std::size_t points = 0;
  for (std::size_t v = 0; v < voxel_capacity; ++v) points += static_cast<std::size_t>(m.voxel_counts[v]);
  source.points.resize(points);
  source.covs.resize(points);
  // a voxel's points are consecutive in the pool: one copy a voxel
  std::size_t i = 0;
  for (std::size_t v = 0; v < voxel_capacity && i < points; ++v) {
    const std::int32_t n = m.voxel_counts[v];
    if (n == 0) continue;
    const std::int64_t first = m.point_index(static_cast<std::int32_t>(v), 0);
    std::copy_n(m.points + first, n, source.points.begin() + static_cast<std::ptrdiff_t>(i));
    std::copy_n(m.covs + first, n, source.covs.begin() + static_cast<std::ptrdiff_t>(i));
    i += static_cast<std::size_t>(n);
  }
}

SourceCloud source_from_map(const map::ConstMapView& m, std::size_t voxel_capacity) {
  SourceCloud source;
  source_from_map(m, voxel_capacity, source);
  return source;
}

FactorParams factor_params(const SE3& T, const Thresholds& th, const RegistrationConfig& config) {
  FactorParams fp;
  fp.R = T.rotation().cast<float>();
  fp.t = T.translation().cast<float>();
  fp.max_correspondence_distance2 = static_cast<float>(th.max_correspondence_m * th.max_correspondence_m);
  fp.kernel.kappa_m = static_cast<float>(th.kernel_scale_m);
  fp.sparsity_aware = config.sparsity_aware;
  fp.skip_line_pairs = config.skip_line_pairs;
  fp.point_to_point_precision = static_cast<float>(th.point_to_point_precision);
  return fp;
}

LinearSystem build_linear_system(const SourceCloud& source, const map::ConstMapView& target, const SE3& T,
                                 const Thresholds& th, const RegistrationConfig& config, exec::CpuExecutor& executor) {
  const FactorParams fp = factor_params(T, th, config);
  const FactorSums sum = executor.accumulate(
      source.size(), FactorSums::zero(),
      [&](FactorSums& acc, std::size_t i) {
        FactorTerms f;
        add_factor(acc, gicp_factor(target, source.points[i], source.covs[i], fp, f), f);
      },
      AddFactorSums{});
  return to_linear_system(sum);
}

std::size_t strided_count(std::size_t n, std::size_t stride) { return stride > 0 ? (n + stride - 1) / stride : n; }

RegistrationResult register_scan(const SourceCloud& source, const map::ConstMapView& target, const SE3& initial_guess,
                                 const Thresholds& th, const RegistrationConfig& config, double time_budget_s,
                                 exec::CpuExecutor& executor) {
  // with correspondence_reuse_m = 0 every point is searched at every iteration
  std::vector<Correspondence> matches(source.size());
  const auto reuse2 = static_cast<float>(config.correspondence_reuse_m * config.correspondence_reuse_m);
  const auto build = [&](const SE3& T, std::size_t stride) {
    const FactorParams fp = factor_params(T, th, config);
    return to_linear_system(executor.accumulate(
        strided_count(source.size(), stride), FactorSums::zero(),
        [&](FactorSums& acc, std::size_t j) {
          const std::size_t i = j * stride;
          FactorTerms f;
          add_factor(acc, gicp_factor_reusing(target, source.points[i], source.covs[i], fp, reuse2, matches[i], f), f);
        },
        AddFactorSums{}));
  };
  return gauss_newton(build, initial_guess, config, time_budget_s);
}

std::string failure_reason(const RegistrationResult& result, std::size_t source_points,
                           const RegistrationConfig& config) {
  if (!result.pose.matrix().allFinite()) return "registration gave a non-finite pose";
  const long inliers = result.system.inliers;
  if (inliers < config.min_inliers) {
    return "too few inliers (" + std::to_string(inliers) + " < registration.min_inliers " +
           std::to_string(config.min_inliers) + ")";
  }
  if (static_cast<double>(inliers) < config.min_inlier_fraction * static_cast<double>(source_points)) {
    return "too few inliers (" + std::to_string(inliers) + " of " + std::to_string(source_points) +
           " points, under registration.min_inlier_fraction)";
  }
  if (result.budget_exceeded) return "registration exceeded its time budget";
  return {};
}

RegistrationResult gauss_newton(const SystemBuilder& build, const SE3& initial_guess, const RegistrationConfig& config,
                                double time_budget_s) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed_s = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  RegistrationResult res;
  res.pose = initial_guess;
  const auto coarse_stride = static_cast<std::size_t>(std::max(1, config.coarse_stride));
  std::size_t stride = 1;  // the first iteration uses every point: a short step never goes coarse
  std::size_t built_stride = 1;
  for (int it = 0; it < config.max_iterations; ++it) {
    res.system = build(res.pose, stride);
    built_stride = stride;
    res.iterations = it + 1;
    if (stride > 1) ++res.coarse_iterations;
    if (res.system.inliers == 0) break;  // nothing to register against: not converged
    const Mat6d H = res.system.H + config.damping * Mat6d::Identity();
    Degeneracy degeneracy;  // none unless held
    if (config.hold_degenerate_directions) {
      degeneracy = analyze_degeneracy(covariance_from_information(H / config.covariance_scale),
                                      static_cast<double>(res.system.inliers), config);
    }
    res.held_directions = degeneracy.degenerate_translations + degeneracy.degenerate_rotations;
    const Vec6d dx = step_without_degenerate_directions(H, res.system.b, degeneracy);
    if (!dx.allFinite()) break;
    res.pose = res.pose * SE3::exp(dx);
    const double step = dx.norm();
    if (stride == 1 && step < config.convergence_norm) {
      res.converged = true;
      break;
    }
    if (elapsed_s() >= time_budget_s) {
      res.budget_exceeded = true;
      break;
    }
    stride = step > config.coarse_step_norm ? coarse_stride : 1;
  }
  // the result carries the system of all points (the fusion's information, the inlier count)
  if (built_stride > 1 && !res.budget_exceeded) res.system = build(res.pose, 1);
  res.time_s = elapsed_s();
  return res;
}

}  // namespace farlio::registration
