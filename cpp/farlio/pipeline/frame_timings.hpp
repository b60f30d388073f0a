#pragma once
// The per-frame stage times of the scan pipeline (timing.csv's *_ms columns).

namespace farlio::pipeline {

/// Time of each stage of one frame, in seconds: wall clock on the CPU backend, CUDA events on
/// the device timeline on the CUDA backend (total_s is wall clock on both).
struct FrameTimings {
  double preprocess_s = 0;  ///< crop, undistortion, downsampling
  double covariance_s = 0;  ///< frame map and source covariances
  double registration_s = 0;
  double map_update_s = 0;  ///< insertion, covariances, removal
  double total_s = 0;
  bool device_timed = false;  ///< the stage times come from CUDA events
};

}  // namespace farlio::pipeline
