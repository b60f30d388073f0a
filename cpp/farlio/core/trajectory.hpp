#pragma once
// A trajectory: time-ordered poses of one frame (say which in the variable or file name).
#include <cstdint>
#include <optional>
#include <vector>

#include "farlio/core/se3.hpp"

namespace farlio {

struct StampedPose {
  std::int64_t stamp_ns = 0;
  SE3 pose;  ///< pose of the frame in the world: maps frame coordinates to world coordinates
};

class Trajectory {
 public:
  Trajectory() = default;
  explicit Trajectory(std::vector<StampedPose> poses) : poses_(std::move(poses)) {}

  void push_back(std::int64_t stamp_ns, const SE3& pose) { poses_.push_back({stamp_ns, pose}); }
  [[nodiscard]] std::size_t size() const { return poses_.size(); }
  [[nodiscard]] bool empty() const { return poses_.empty(); }
  [[nodiscard]] const StampedPose& operator[](std::size_t i) const { return poses_[i]; }
  [[nodiscard]] const std::vector<StampedPose>& poses() const { return poses_; }
  [[nodiscard]] auto begin() const { return poses_.begin(); }
  [[nodiscard]] auto end() const { return poses_.end(); }

  /// True if stamps strictly increase.
  [[nodiscard]] bool is_time_ordered() const;
  /// Pose at stamp_ns by geodesic interpolation between neighbours; nullopt outside the
  /// covered time span (no extrapolation). Requires a time-ordered trajectory.
  [[nodiscard]] std::optional<SE3> interpolate_at(std::int64_t stamp_ns) const;
  /// Every pose right-multiplied by `extrinsic` (e.g. body poses -> LiDAR poses with T_body_lidar).
  [[nodiscard]] Trajectory transformed(const SE3& extrinsic) const;
  /// The poses stamped within [begin_ns, end_ns] (a stretch of the run).
  [[nodiscard]] Trajectory between(std::int64_t begin_ns, std::int64_t end_ns) const;
  /// Path length in metres (sum of translation increments).
  [[nodiscard]] double path_length_m() const;

 private:
  std::vector<StampedPose> poses_;
};

}  // namespace farlio
