#pragma once
// The per-point bodies of the scan preprocessing, shared by the CPU backend and CUDA: range crop
// of the raw point and the key of its downsampling cell (the first point of each cell in (key,
// input order) is kept by both backends), then the undistortion of each kept point into the
// scan-end frame.
#include <Eigen/Core>
#include <cstdint>

#include "farlio/deskew/scan_motion.hpp"
#include "farlio/exec/hd.hpp"
#include "farlio/exec/hd_math.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/preprocess/range_crop.hpp"

namespace farlio::preprocess {

struct PreprocessParams {
  RangeCrop crop;
  deskew::DeskewTable motion;  ///< the scan's motion (DeskewTable::sample), read when undistort
  bool undistort = false;
  float inv_cell_m = 1.0f;  ///< 1 / downsampling cell (the map spacing)
};

/// Whether the raw point has finite coordinates and, where the scan has times (`time` not null), a
/// finite time: the points that Scan::remove_non_finite keeps. A backend that screens the scan
/// itself (the CUDA backend, on the device) drops the others with this test.
FARLIO_HD inline bool finite_point(const Eigen::Vector3f& raw, const float* time) {
  return exec::is_finite(raw.x()) && exec::is_finite(raw.y()) && exec::is_finite(raw.z()) &&
         (time == nullptr || exec::is_finite(*time));
}

/// The key of the raw point's downsampling cell, or kEmptyKey for a cropped, non-finite or
/// out-of-range point. The cells are those of the raw positions: only the point kept in each cell
/// is then undistorted (undistorted_point), ~10k points instead of the scan's ~120k. A cell's
/// neighbours in the scan were measured microseconds apart, so the distortion shifts them alike
/// and the kept points keep the map spacing (docs/performance.md, "Only the kept points are undistorted").
FARLIO_HD inline std::uint64_t downsampling_key(const Eigen::Vector3f& raw, const PreprocessParams& pp) {
  return pp.crop.keeps(raw) ? map::point_key(raw, pp.inv_cell_m) : map::kEmptyKey;
}

/// The raw point measured at `tau_s` (s since the scan's start) in the sensor frame at the scan's
/// end; the raw point itself when the scan is not undistorted.
FARLIO_HD inline Eigen::Vector3f undistorted_point(const Eigen::Vector3f& raw, float tau_s,
                                                   const PreprocessParams& pp) {
  return pp.undistort ? deskew::deskew_point(pp.motion, raw, tau_s) : raw;
}

}  // namespace farlio::preprocess
