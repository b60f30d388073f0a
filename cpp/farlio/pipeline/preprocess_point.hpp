#pragma once
// The per-point body of the scan preprocessing, shared by the CPU backend and CUDA: range crop
// of the raw point, undistortion into the scan-end frame, and the key of its downsampling cell
// (the first point of each cell in (key, input order) is kept by both backends).
#include <Eigen/Core>
#include <cstdint>

#include "farlio/deskew/scan_motion.hpp"
#include "farlio/exec/hd.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/range_crop.hpp"

namespace farlio::pipeline {

struct PreprocessParams {
  RangeCrop crop;
  deskew::DeskewTable motion;  ///< the scan's motion (DeskewTable::sample), read when undistort
  bool undistort = false;
  float inv_cell_m = 1.0f;  ///< 1 / downsampling cell (the map spacing)
};

/// Writes the undistorted point to *out (when kept by the crop) and returns its cell key, or
/// kEmptyKey for a cropped, non-finite or out-of-range point. `tau_s` is read only to undistort.
FARLIO_HD inline std::uint64_t preprocess_point(const Eigen::Vector3f& raw, float tau_s, const PreprocessParams& pp,
                                                Eigen::Vector3f* out) {
  if (!pp.crop.keeps(raw)) return map::kEmptyKey;
  const Eigen::Vector3f p = pp.undistort ? deskew::deskew_point(pp.motion, raw, tau_s) : raw;
  *out = p;
  return map::point_key(p, pp.inv_cell_m);
}

}  // namespace farlio::pipeline
