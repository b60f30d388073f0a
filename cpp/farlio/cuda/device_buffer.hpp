#pragma once
// A device array allocated once with a fixed capacity (cudaMalloc in the constructor, cudaFree
// in the destructor); it never grows. Copies check the element count against the capacity on
// the host and throw CapacityError naming the config field to raise.
#include <cuda_runtime_api.h>

#include <cstddef>
#include <string>
#include <utility>

#include "farlio/core/error.hpp"
#include "farlio/cuda/cuda_check.hpp"

namespace farlio::cuda {

template <typename T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  /// `name` appears in capacity errors (e.g. "scan points").
  DeviceBuffer(std::size_t capacity, std::string name) : capacity_(capacity), name_(std::move(name)) {
    if (capacity_ > 0) FARLIO_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&data_), bytes()));
  }
  ~DeviceBuffer() { release(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)), capacity_(std::exchange(o.capacity_, 0)), name_(std::move(o.name_)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) {
      release();
      data_ = std::exchange(o.data_, nullptr);
      capacity_ = std::exchange(o.capacity_, 0);
      name_ = std::move(o.name_);
    }
    return *this;
  }

  [[nodiscard]] T* data() const { return data_; }
  [[nodiscard]] std::size_t capacity() const { return capacity_; }
  [[nodiscard]] std::size_t bytes() const { return capacity_ * sizeof(T); }

  /// Throws CapacityError when n elements do not fit; `parameter` is the config field to raise.
  void require(std::size_t n, const char* parameter) const {
    if (n <= capacity_) return;
    throw CapacityError("CUDA backend: " + std::to_string(n) + " " + name_ + " do not fit the device buffer of " +
                        std::to_string(capacity_) + "; raise " + parameter);
  }
  /// Copies n elements from the host into [offset, offset + n), asynchronously on `stream`.
  void upload(const T* host, std::size_t n, cudaStream_t stream, const char* parameter, std::size_t offset = 0) {
    require(offset + n, parameter);
    if (n > 0) FARLIO_CUDA_CHECK(cudaMemcpyAsync(data_ + offset, host, n * sizeof(T), cudaMemcpyHostToDevice, stream));
  }
  /// Copies the first n elements to the host and waits for them.
  void download(T* host, std::size_t n, cudaStream_t stream) const {
    require(n, "(a download larger than the buffer)");
    if (n == 0) return;
    FARLIO_CUDA_CHECK(cudaMemcpyAsync(host, data_, n * sizeof(T), cudaMemcpyDeviceToHost, stream));
    FARLIO_CUDA_CHECK(cudaStreamSynchronize(stream));
  }

 private:
  void release() noexcept {
    if (data_) cudaFree(data_);  // no throw from a destructor; a failed free leaks at worst
    data_ = nullptr;
  }

  T* data_ = nullptr;
  std::size_t capacity_ = 0;
  std::string name_;
};

}  // namespace farlio::cuda
