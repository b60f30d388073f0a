#pragma once
// Sparsity-aware GICP, scan to submap (paper section III-A): Gauss-Newton on SE(3) over the
// per-point factors of gicp_factor.hpp, correspondences limited to 3 sigma and the Cauchy
// kernel scale kappa = sigma / 3 (KISS-ICP's adaptive threshold), stopped when |dx| falls below
// the convergence norm or the time budget runs out. Returns the pose with the linear system.
#include <functional>
#include <string>
#include <vector>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/map_view.hpp"
#include "farlio/registration/gicp_factor.hpp"
#include "farlio/registration/linear_system.hpp"

namespace farlio::registration {

/// Registration input: points in the sensor frame, w = their map::PointShape.
struct SourceCloud {
  std::vector<Eigen::Vector4f> points;
  std::vector<map::Cov3> covs;
  [[nodiscard]] std::size_t size() const { return points.size(); }
};

struct RegistrationResult {
  SE3 pose;             ///< registered sensor pose in the map frame
  LinearSystem system;  ///< the system of the last iteration (at the pose before its step)
  int iterations = 0;
  bool converged = false;        ///< |dx| fell below the convergence norm
  bool budget_exceeded = false;  ///< stopped by the time budget
  int held_directions = 0;       ///< degenerate directions held at the guess in the last step
  int coarse_iterations = 0;     ///< of the iterations, those on every coarse_stride-th source point
  double time_s = 0.0;
};

/// The stored points of a map with their covariances (the per-scan frame map gives the source).
SourceCloud source_from_map(const map::ConstMapView& frame_map, std::size_t voxel_capacity);
/// The same into `source`, whose buffers are kept (no allocation per scan once they are large
/// enough).
void source_from_map(const map::ConstMapView& frame_map, std::size_t voxel_capacity, SourceCloud& source);

/// Correspondence distance (3 sigma) and kernel scale (sigma / 3), as in KISS-ICP, and the
/// weight of point-to-point factors.
struct Thresholds {
  double max_correspondence_m;
  double kernel_scale_m;
  double point_to_point_precision = 1.0;  ///< see point_to_point_precision()
  static Thresholds from_sigma(double sigma_m, double p2p_precision = 1.0) {
    return {3.0 * sigma_m, sigma_m / 3.0, p2p_precision};
  }
};

/// The per-factor parameters at pose T (what every backend hands the shared factor body).
FactorParams factor_params(const SE3& T, const Thresholds& th, const RegistrationConfig& config);

/// The precision of a point-to-point factor in the units of the GICP factors, whose
/// covariances are Frobenius-normalised so that a surface's normal variance of about
/// covariance_epsilon (m^2) counts as 1: epsilon / sigma^2, with sigma from
/// config.point_to_point_sigma_m or half the spacing.
double point_to_point_precision(const RegistrationConfig& config, double covariance_epsilon, double spacing_m);

/// The linear system of `source` at pose T against the map.
LinearSystem build_linear_system(const SourceCloud& source, const map::ConstMapView& target, const SE3& T,
                                 const Thresholds& th, const RegistrationConfig& config, exec::CpuExecutor& executor);

RegistrationResult register_scan(const SourceCloud& source, const map::ConstMapView& target, const SE3& initial_guess,
                                 const Thresholds& th, const RegistrationConfig& config, double time_budget_s,
                                 exec::CpuExecutor& executor);

/// Why a registration's pose must not be used (empty when it may): a non-finite pose, fewer
/// inliers than config.min_inliers or than config.min_inlier_fraction of the source's points, or
/// stopped by the time budget before converging.
std::string failure_reason(const RegistrationResult& result, std::size_t source_points,
                           const RegistrationConfig& config);

/// How many of n points the stride visits: 0, stride, 2 stride, ... < n.
std::size_t strided_count(std::size_t n, std::size_t stride);

/// Builds the linear system at pose T of the source points 0, stride, 2 stride, ... (a backend's
/// reduction; stride 1: all of them).
using SystemBuilder = std::function<LinearSystem(const SE3&, std::size_t stride)>;

/// The Gauss-Newton loop on SE(3), whatever backend builds the systems: stops at convergence,
/// without inliers, or when the time budget is spent. With hold_degenerate_directions, each step
/// leaves the pose unchanged along the directions the system does not constrain (degeneracy.hpp).
/// Coarse to fine: after a step longer than config.coarse_step_norm the next iteration uses every
/// config.coarse_stride-th point; convergence is only declared on all points, and the result's
/// system is always that of all points.
RegistrationResult gauss_newton(const SystemBuilder& build, const SE3& initial_guess, const RegistrationConfig& config,
                                double time_budget_s);

}  // namespace farlio::registration
