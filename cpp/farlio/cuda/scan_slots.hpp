#pragma once
// A scan's points and times on the device, in one of two slots. ScanBackend::stage_next hands
// over the scan after the one about to be processed; a worker thread copies it into page-locked
// memory and queues its copy into a slot on a stream of its own while the frame's kernels run (in
// the frame, the host's copy and the bus took 0.09-0.20 ms of a 0.65-0.85 ms frame on an H200,
// docs/cuda.md). A scan that was not staged goes up in its frame, through page-locked memory on
// the frame's stream.
//
// Scans back to back (stage k+1, process k, stage k+2, ...): when k+1 is staged, scan k waits
// staged in one slot and scan k-1's frame is done with the other, which k+1 takes. A slot is
// taken by a staged scan or an upload only when no staged scan waits in it, or when both slots
// hold one (the older one is then dropped). A staged copy waits for the frame stream's work queued
// before stage() (the earlier frames' reads of its slot); the frame's stream waits for the staged
// copy it takes, or for a dropped one still writing into the slot it uploads to. The frame's host
// waits for the worker only for the slot the worker is copying into. Plain C++ header.
#include <cuda_runtime_api.h>

#include <Eigen/Core>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "farlio/core/types.hpp"
#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/staged_upload.hpp"

namespace farlio::cuda {

/// One job at a time on a thread of its own; wait() returns once the job is done and rethrows
/// what it threw.
class BackgroundJob {
 public:
  BackgroundJob();
  ~BackgroundJob();
  BackgroundJob(const BackgroundJob&) = delete;
  BackgroundJob& operator=(const BackgroundJob&) = delete;

  /// Waits for the running job, then starts `job`.
  void start(std::function<void()> job);
  /// Waits until no job runs; rethrows the exception of the last job, once.
  void wait();

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;
  bool busy_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts once the rest is constructed
};

class ScanSlots {
 public:
  /// A slot's device arrays.
  struct Slot {
    const Eigen::Vector3f* points = nullptr;
    const float* times = nullptr;
  };

  /// `max_points` a slot (cuda.max_scan_points, named in errors); `threads`: host threads of the
  /// copies into page-locked memory; `frame_stream`: the stream of the frame's kernels.
  ScanSlots(std::size_t max_points, int threads, cudaStream_t frame_stream);
  ~ScanSlots();
  ScanSlots(const ScanSlots&) = delete;
  ScanSlots& operator=(const ScanSlots&) = delete;

  /// Starts moving `next` into a slot and returns at once (the host's part runs on the worker).
  /// `next` must stay alive and unchanged until take() of it, the next stage() or the
  /// destructor. A scan beyond the slots' size is not staged (take() then says so).
  void stage(const Scan& next);
  /// `scan` on the device, on the frame stream's timeline: its slot when it was staged (the same
  /// object, unchanged), else uploaded now. Its times go up when it has them, staged or not.
  Slot take(const Scan& scan);

  /// Whether the last take() found its scan staged.
  [[nodiscard]] bool last_was_staged() const { return last_staged_; }
  /// The page-locked staging of the frame's own uploads (the bandwidth measurement's).
  [[nodiscard]] StagedUpload& frame_staging() { return frame_staging_; }
  [[nodiscard]] std::size_t device_bytes() const;

 private:
  /// What tells a scan from another: its arrays and its end stamp.
  struct Identity {
    const void* points = nullptr;
    std::size_t n = 0;
    const void* times = nullptr;
    std::size_t n_times = 0;
    std::int64_t end_stamp_ns = 0;
    static Identity of(const Scan& s);
    bool operator==(const Identity&) const = default;
  };
  /// A slot for a new scan: one where no staged scan waits, the last frame's first; else the
  /// one whose staged scan is older (dropped).
  int free_slot();
  /// Waits for the worker's job (its copies are then queued) and rethrows what it threw.
  void finish_job();
  /// Queues the copy of `scan`'s points, and its times when it has them, into `slot` through
  /// `staging` on `stream`.
  void upload(const Scan& scan, int slot, StagedUpload& staging, cudaStream_t stream);
  [[nodiscard]] Slot slot(int s) const { return {points_[s].data(), times_[s].data()}; }

  static constexpr int kSlots = 2;
  std::size_t max_points_;
  cudaStream_t frame_stream_;
  int device_ = 0;  // the frame stream's device: the worker's CUDA calls go to it
  cudaStream_t copy_stream_ = nullptr;
  DeviceBuffer<Eigen::Vector3f> points_[kSlots];
  DeviceBuffer<float> times_[kSlots];
  cudaEvent_t frame_queued_ = nullptr;     // the frame stream's work queued before a stage()
  cudaEvent_t staged_ready_[kSlots] = {};  // after the staged copy into the slot
  bool staged_[kSlots] = {};               // a staged scan waits in the slot
  Identity staged_scan_[kSlots];
  std::uint64_t staged_order_[kSlots] = {};  // when it was staged (stage() calls)
  std::uint64_t stages_ = 0;
  StagedUpload frame_staging_;  // the frame's own uploads (the calling thread)
  StagedUpload next_staging_;   // the staged ones (the worker)
  static constexpr int kNoSlot = -1;
  int current_ = 0;         // the slot of the last take()
  int job_slot_ = kNoSlot;  // the slot the worker's job may still be copying into
  bool last_staged_ = false;
  BackgroundJob worker_;  // last: its thread stops before the buffers go
};

}  // namespace farlio::cuda
