#include "farlio/cuda/scan_slots.hpp"

#include <utility>

#include "farlio/cuda/cuda_check.hpp"

namespace farlio::cuda {
namespace {

constexpr const char* kScanParameter = "cuda.max_scan_points";

/// Bytes of page-locked memory a slot's upload needs at most: its points and times.
std::size_t slot_bytes(std::size_t max_points) { return max_points * (sizeof(Eigen::Vector3f) + sizeof(float)); }

cudaEvent_t new_event() {
  cudaEvent_t e = nullptr;
  FARLIO_CUDA_CHECK(cudaEventCreateWithFlags(&e, cudaEventDisableTiming));
  return e;
}

}  // namespace

BackgroundJob::BackgroundJob() : thread_([this] { run(); }) {}

BackgroundJob::~BackgroundJob() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void BackgroundJob::start(std::function<void()> job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  job_ = std::move(job);
  busy_ = true;
  lock.unlock();
  changed_.notify_all();
}

void BackgroundJob::wait() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !busy_; });
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void BackgroundJob::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return busy_ || stop_; });
    if (!busy_) return;  // stopped with nothing to do
    std::function<void()> job = std::move(job_);
    lock.unlock();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    error_ = error;
    busy_ = false;
    changed_.notify_all();
  }
}

ScanSlots::Identity ScanSlots::Identity::of(const Scan& s) {
  return {s.points.data(), s.points.size(), s.time_s.data(), s.time_s.size(), s.end_stamp_ns};
}

ScanSlots::ScanSlots(std::size_t max_points, int threads, cudaStream_t frame_stream)
    : max_points_(max_points),
      frame_stream_(frame_stream),
      points_{DeviceBuffer<Eigen::Vector3f>(max_points, "scan points"),
              DeviceBuffer<Eigen::Vector3f>(max_points, "scan points")},
      times_{DeviceBuffer<float>(max_points, "scan points"), DeviceBuffer<float>(max_points, "scan points")},
      frame_staging_(slot_bytes(max_points), threads),
      next_staging_(slot_bytes(max_points), threads) {
  FARLIO_CUDA_CHECK(cudaGetDevice(&device_));
  FARLIO_CUDA_CHECK(cudaStreamCreateWithFlags(&copy_stream_, cudaStreamNonBlocking));
  frame_queued_ = new_event();
  for (cudaEvent_t& e : staged_ready_) e = new_event();
}

ScanSlots::~ScanSlots() {
  // no throw from a destructor: the worker's last copies are queued, then they have landed
  try {
    finish_job();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a failed staging leaves nothing to undo
  }
  if (copy_stream_) cudaStreamSynchronize(copy_stream_);
  for (cudaEvent_t e : staged_ready_) {
    if (e) cudaEventDestroy(e);
  }
  if (frame_queued_) cudaEventDestroy(frame_queued_);
  if (copy_stream_) cudaStreamDestroy(copy_stream_);
}

int ScanSlots::free_slot() {
  if (!staged_[current_]) return current_;
  const int other = 1 - current_;
  if (!staged_[other]) return other;
  const int older = staged_order_[current_] < staged_order_[other] ? current_ : other;
  staged_[older] = false;  // dropped
  return older;
}

void ScanSlots::upload(const Scan& scan, int slot, StagedUpload& staging, cudaStream_t stream) {
  const std::size_t n = scan.size();
  points_[slot].require(n, kScanParameter);
  staging.begin_frame();
  staging.upload(scan.points.data(), points_[slot].data(), n * sizeof(Eigen::Vector3f), stream);
  if (scan.has_time()) staging.upload(scan.time_s.data(), times_[slot].data(), n * sizeof(float), stream);
}

void ScanSlots::finish_job() {
  job_slot_ = kNoSlot;
  worker_.wait();
}

void ScanSlots::stage(const Scan& next) {
  finish_job();                           // the last staged scan's host part is done: the worker's memory can be reused
  if (next.size() > max_points_) return;  // take() names the field to raise
  const int slot = free_slot();
  job_slot_ = slot;
  staged_[slot] = true;
  staged_scan_[slot] = Identity::of(next);
  staged_order_[slot] = ++stages_;
  // the copy waits for the frame stream's work queued so far: the last frames' reads of the slot
  // (the frame that follows reads the other slot, or waits for this copy)
  FARLIO_CUDA_CHECK(cudaEventRecord(frame_queued_, frame_stream_));
  FARLIO_CUDA_CHECK(cudaStreamWaitEvent(copy_stream_, frame_queued_, 0));
  worker_.start([this, &next, slot] {
    FARLIO_CUDA_CHECK(cudaSetDevice(device_));  // a thread's current device is its own
    upload(next, slot, next_staging_, copy_stream_);
    FARLIO_CUDA_CHECK(cudaEventRecord(staged_ready_[slot], copy_stream_));
  });
}

ScanSlots::Slot ScanSlots::take(const Scan& scan) {
  // Scans back to back: the worker is busy with the next scan, staged into the other slot while
  // this one's copy has long been queued; the frame waits for the worker only for the slot the
  // worker writes into.
  const Identity id = Identity::of(scan);
  for (int s = 0; s < kSlots; ++s) {
    if (staged_[s] && staged_scan_[s] == id) {
      if (s == job_slot_) finish_job();  // its copy is queued once the job is done
      staged_[s] = false;
      current_ = s;
      last_staged_ = true;
      FARLIO_CUDA_CHECK(cudaStreamWaitEvent(frame_stream_, staged_ready_[s], 0));
      return slot(s);
    }
  }
  last_staged_ = false;
  current_ = free_slot();
  if (current_ == job_slot_) finish_job();  // a staged scan dropped: its copies are queued
  // a staged copy that was dropped may still be writing into the slot
  FARLIO_CUDA_CHECK(cudaStreamWaitEvent(frame_stream_, staged_ready_[current_], 0));
  upload(scan, current_, frame_staging_, frame_stream_);
  return slot(current_);
}

std::size_t ScanSlots::device_bytes() const {
  std::size_t bytes = 0;
  for (int s = 0; s < kSlots; ++s) bytes += points_[s].bytes() + times_[s].bytes();
  return bytes;
}

}  // namespace farlio::cuda
