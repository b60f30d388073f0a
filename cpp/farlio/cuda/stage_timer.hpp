#pragma once
// Per-stage times of one frame on the device timeline: a pair of CUDA events per stage,
// recorded on the backend's stream; read once per frame into FrameTimings.
#include <cuda_runtime_api.h>

#include <array>

#include "farlio/pipeline/frame_timings.hpp"

namespace farlio::cuda {

class StageTimer {
 public:
  enum Stage { kPreprocess, kSource, kRegistration, kMapUpdate, kStages };

  explicit StageTimer(cudaStream_t stream);
  ~StageTimer();
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

  /// Forgets the stages of the previous frame.
  void new_frame() { recorded_.fill(false); }
  void start(Stage s);
  void stop(Stage s);
  /// Writes the recorded stages' times (0 for stages not run) into t; waits for the events.
  void read(pipeline::FrameTimings& t) const;

 private:
  cudaStream_t stream_;
  std::array<cudaEvent_t, kStages> start_{};
  std::array<cudaEvent_t, kStages> stop_{};
  std::array<bool, kStages> recorded_{};
};

}  // namespace farlio::cuda
