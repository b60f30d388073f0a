#pragma once
// The per-point factor of the sparsity-aware GICP (paper eqs. 3-5), a kernel body shared by the
// CPU executor and CUDA. For a source point s with covariance C_s (sensor frame) and the
// current pose T = (R, t): p = R s + t is matched to its nearest map point q within the
// correspondence distance; the residual r = p - q is weighted by
//   Omega = (C_q + R C_s R^T)^-1   when both covariances exist (GICP),
//   Omega = lambda I               otherwise (Sigma_r = I / lambda, Sigma_s = 0: point-to-point;
//                                  the paper's lambda is 1, farlio's the map spacing's),
// and by the Cauchy weight of |r|. A pair of two line-like covariances is left out with
// skip_line_pairs. Plain ICP (sparsity_aware false) uses Omega = I for every pair. The Jacobian of r under a right
// perturbation T exp(delta), delta = [rho; phi], is J = [R, -R [s]x].
#include <Eigen/Core>
#include <cstdint>

#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"
#include "farlio/map/covariance.hpp"
#include "farlio/map/map_view.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/registration/robust_kernel.hpp"

namespace farlio::registration {

/// One factor's contribution in float: the upper triangle of H (21), b (6), cost, inlier flag.
struct FactorTerms {
  float H[21];
  float b[6];
  float cost;
  int inlier;
};

struct FactorParams {
  Eigen::Matrix3f R;
  Eigen::Vector3f t;
  float max_correspondence_distance2;
  CauchyKernel kernel;
  bool sparsity_aware;
  bool skip_line_pairs = true;
  float point_to_point_precision = 1.0f;  ///< lambda, in the Frobenius-normalised units of Omega
};

/// The factor of source point `s` (w = 1 if `cov_s` is valid) at its transformed position
/// p = R s + t, matched to map point `nn` (-1: none). Returns false (and leaves `out` untouched)
/// when there is no correspondence within the distance.
///
/// With J = R [I, -[s]x] the blocks of J^T Omega J need only A = R^T Omega R, which for GICP is
/// (R^T C_q R + C_s)^-1: H = w [A, -A S; S A, -S A S] and b = w [A r'; s x (A r')] with S = [s]x
/// and r' = R^T r, about half the arithmetic of forming J and the 6x6 product; the inverse from
/// the symmetric cofactors (tests/cpp/test_gicp.cpp checks it against that product).
FARLIO_HD inline bool gicp_factor_at(const map::ConstMapView& m, const Eigen::Vector4f& s, const map::Cov3& cov_s,
                                     const Eigen::Vector3f& p, std::int64_t nn, const FactorParams& fp,
                                     FactorTerms& out) {
  if (nn < 0) return false;
  const Eigen::Vector4f& q = m.points[nn];
  const Eigen::Vector3f r = p - q.head<3>();
  const float r2 = r.squaredNorm();
  if (!(r2 <= fp.max_correspondence_distance2)) return false;  // a reused match that moved out of the gate
  const bool both_covariances = map::has_covariance(s) && map::has_covariance(q);
  if (fp.sparsity_aware && fp.skip_line_pairs && map::is_line_like(s) && map::is_line_like(q)) return false;
  // A = R^T Omega R: Omega = I (plain ICP), lambda I (point-to-point), (C_q + R C_s R^T)^-1 (GICP)
  Eigen::Matrix3f A = Eigen::Matrix3f::Identity();
  if (fp.sparsity_aware) A *= fp.point_to_point_precision;
  if (fp.sparsity_aware && both_covariances) {
    const Eigen::Matrix3f c = fp.R.transpose() * m.covs[nn].matrix() * fp.R + cov_s.matrix();
    const Eigen::Matrix3f inv = map::SymmetricCofactors(c).inverse();
    if (exec::all_finite(inv)) A = inv;
  }
  const float w = fp.kernel.weight(r2);
  const float x = s.x(), y = s.y(), z = s.z();
  // B = A S, column by column (S's columns: (0, z, -y), (-z, 0, x), (y, -x, 0))
  Eigen::Matrix3f B;
  B.col(0) = z * A.col(1) - y * A.col(2);
  B.col(1) = x * A.col(2) - z * A.col(0);
  B.col(2) = y * A.col(0) - x * A.col(1);
  // S B, row by row (S's rows: (0, -z, y), (z, 0, -x), (-y, x, 0)); H_rr = -S B
  Eigen::Matrix3f SB;
  SB.row(0) = y * B.row(2) - z * B.row(1);
  SB.row(1) = z * B.row(0) - x * B.row(2);
  SB.row(2) = x * B.row(1) - y * B.row(0);
  const Eigen::Vector3f v = A * (fp.R.transpose() * r);
  const Eigen::Vector3f sv = s.head<3>().cross(v);
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) out.H[k++] = w * A(i, j);
    for (int j = 0; j < 3; ++j) out.H[k++] = -w * B(i, j);
    out.b[i] = w * v(i);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) out.H[k++] = -w * SB(i, j);
    out.b[3 + i] = w * sv(i);
  }
  out.cost = fp.kernel.cost(r2);
  out.inlier = 1;
  return true;
}

/// Computes the factor of source point `s` with its nearest map point searched at the current
/// pose. Returns false (and leaves `out` untouched) when there is no correspondence within the
/// distance.
FARLIO_HD inline bool gicp_factor(const map::ConstMapView& m, const Eigen::Vector4f& s, const map::Cov3& cov_s,
                                  const FactorParams& fp, FactorTerms& out) {
  const Eigen::Vector3f p = fp.R * s.head<3>() + fp.t;
  return gicp_factor_at(m, s, cov_s, p, map::nearest_neighbor(m, p, fp.max_correspondence_distance2), fp, out);
}

/// One source point's correspondence kept across Gauss-Newton iterations: the map point found
/// and where the point was when it was searched.
struct Correspondence {
  Eigen::Vector3f searched_at;
  std::int64_t nn = -1;
  bool valid = false;  ///< false before the first search
};

/// Whether a point now at p is searched again: it has no correspondence yet, or it moved by
/// sqrt(reuse_distance2) or more since its last search.
FARLIO_HD inline bool search_again(const Correspondence& c, const Eigen::Vector3f& p, float reuse_distance2) {
  return !c.valid || !((p - c.searched_at).squaredNorm() < reuse_distance2);
}

/// gicp_factor, but the nearest neighbour is searched again only when the point moved by
/// `reuse_distance_m` or more since its last search (the iterations after the first move most
/// points by millimetres, which changes almost no match); `c` is updated.
FARLIO_HD inline bool gicp_factor_reusing(const map::ConstMapView& m, const Eigen::Vector4f& s, const map::Cov3& cov_s,
                                          const FactorParams& fp, float reuse_distance2, Correspondence& c,
                                          FactorTerms& out) {
  const Eigen::Vector3f p = fp.R * s.head<3>() + fp.t;
  if (search_again(c, p, reuse_distance2)) {
    c.nn = map::nearest_neighbor(m, p, fp.max_correspondence_distance2);
    c.searched_at = p;
    c.valid = true;
  }
  return gicp_factor_at(m, s, cov_s, p, c.nn, fp, out);
}

}  // namespace farlio::registration
