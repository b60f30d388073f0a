#include "farlio/cuda/stage_timer.hpp"

#include "farlio/cuda/cuda_check.hpp"

namespace farlio::cuda {
namespace {
constexpr double kSecondsPerMs = 1e-3;
}

StageTimer::StageTimer(cudaStream_t stream) : stream_(stream) {
  for (int s = 0; s < kStages; ++s) {
    FARLIO_CUDA_CHECK(cudaEventCreate(&start_[s]));
    FARLIO_CUDA_CHECK(cudaEventCreate(&stop_[s]));
  }
}

StageTimer::~StageTimer() {
  for (int s = 0; s < kStages; ++s) {  // no throw from a destructor
    if (start_[s]) cudaEventDestroy(start_[s]);
    if (stop_[s]) cudaEventDestroy(stop_[s]);
  }
}

void StageTimer::start(Stage s) { FARLIO_CUDA_CHECK(cudaEventRecord(start_[s], stream_)); }

void StageTimer::stop(Stage s) {
  FARLIO_CUDA_CHECK(cudaEventRecord(stop_[s], stream_));
  recorded_[s] = true;
}

void StageTimer::read(pipeline::FrameTimings& t) const {
  double* out[kStages] = {&t.preprocess_s, &t.covariance_s, &t.registration_s, &t.map_update_s};
  for (int s = 0; s < kStages; ++s) {
    float ms = 0.0f;
    if (recorded_[s]) {
      FARLIO_CUDA_CHECK(cudaEventSynchronize(stop_[s]));
      FARLIO_CUDA_CHECK(cudaEventElapsedTime(&ms, start_[s], stop_[s]));
    }
    *out[s] = static_cast<double>(ms) * kSecondsPerMs;
  }
  t.device_timed = true;
}

}  // namespace farlio::cuda
