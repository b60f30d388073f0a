// The executor's one-launch reduction and the read-back: exact integer sums for sizes around the
// block and grid boundaries, the same bits twice for a float sum, several results in one wait,
// and the read-back's bounds. (A .cu file: the reductions take device lambdas.)
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "cuda_test_support.hpp"
#include "farlio/cuda/cuda_executor.cuh"
#include "farlio/cuda/read_back.hpp"

using namespace farlio;
namespace gpu = farlio::cuda;  // (CCCL has a ::cuda namespace too)

namespace {

constexpr std::size_t kBlockItems = gpu::CudaExecutor::kReduceThreads;
constexpr std::size_t kGridItems = kBlockItems * gpu::CudaExecutor::kMaxReduceBlocks;
// sizes around one block, one full grid (the last block count) and beyond (grid-stride)
const std::vector<std::size_t> kSizes = {
    0, 1, kBlockItems - 1, kBlockItems, kBlockItems + 1, kGridItems - 1, kGridItems, kGridItems + 1, 1000003};

long long gauss_sum(std::size_t n) { return static_cast<long long>(n) * (static_cast<long long>(n) - 1) / 2; }

/// sum of i over [0, n) on the device (read back by reduce()). The device lambdas live in named
/// functions: nvcc takes none in a test body (a private member function).
long long device_index_sum(gpu::CudaExecutor& ex, std::size_t n) {
  return ex.reduce(
      n, 0LL, [] __device__(std::size_t i) { return static_cast<long long>(i); }, gpu::Add{});
}

/// The same sum into *out (no wait).
void device_index_sum_into(gpu::CudaExecutor& ex, std::size_t n, long long* out) {
  ex.reduce_into(
      n, 0LL, [] __device__(std::size_t i) { return static_cast<long long>(i); }, gpu::Add{}, out);
}

/// sum of 1 / (i + 1) over [0, n) on the device, into *out (no wait).
void device_harmonic_sum(gpu::CudaExecutor& ex, std::size_t n, double* out) {
  ex.reduce_into(
      n, 0.0, [] __device__(std::size_t i) { return 1.0 / static_cast<double>(i + 1); }, gpu::Add{}, out);
}

}  // namespace

TEST(CudaExecutor, OneLaunchReductionGivesTheExactSumAtEverySize) {
  FARLIO_REQUIRE_GPU();
  gpu::CudaExecutor ex;
  // twice over, sizes alternating: a block count left behind by one launch would leave the next
  // result unwritten (the previous value, another size's sum)
  for (int round = 0; round < 2; ++round) {
    for (const std::size_t n : kSizes) EXPECT_EQ(device_index_sum(ex, n), gauss_sum(n)) << "n = " << n;
  }
}

TEST(CudaExecutor, AFloatSumIsTheSameBitsEveryTimeAndCloseToTheSerialSum) {
  FARLIO_REQUIRE_GPU();
  gpu::CudaExecutor ex;
  constexpr std::size_t kN = 777777;
  constexpr double kRelTol = 1e-12;
  gpu::DeviceBuffer<double> out(2, "sums");
  device_harmonic_sum(ex, kN, out.data());
  device_harmonic_sum(ex, kN, out.data() + 1);
  double sums[2];
  out.download(sums, 2, ex.stream());
  EXPECT_EQ(sums[0], sums[1]);  // the partials are combined in block order whichever block ends last
  double serial = 0.0;
  for (std::size_t i = 0; i < kN; ++i) serial += 1.0 / static_cast<double>(i + 1);
  EXPECT_NEAR(sums[0], serial, kRelTol * serial);
}

TEST(CudaExecutor, SeveralResultsComeBackInOneWait) {
  FARLIO_REQUIRE_GPU();
  gpu::CudaExecutor ex;
  gpu::DeviceBuffer<long long> sums(3, "sums");
  const std::size_t sizes[3] = {5, kGridItems + 7, 0};
  for (int i = 0; i < 3; ++i) device_index_sum_into(ex, sizes[i], sums.data() + i);
  gpu::ReadBack& rb = ex.read_back();
  rb.clear();
  const gpu::ReadSlot<long long> first = rb.post(sums.data(), 2);
  const gpu::ReadSlot<long long> last = rb.post(sums.data() + 2);
  rb.wait();
  EXPECT_EQ(rb.value(first, 0), gauss_sum(sizes[0]));
  EXPECT_EQ(rb.value(first, 1), gauss_sum(sizes[1]));
  EXPECT_EQ(rb.value(last), 0);  // an empty reduction writes the identity
}

TEST(CudaExecutor, TheReadBackRefusesMoreThanItHoldsAndReadsOfWhatWasNotPosted) {
  FARLIO_REQUIRE_GPU();
  gpu::CudaExecutor ex;
  gpu::ReadBack& rb = ex.read_back();
  rb.clear();
  gpu::DeviceBuffer<std::uint8_t> bytes(gpu::ReadBack::kBytes + 1, "bytes");
  FARLIO_CUDA_CHECK(cudaMemsetAsync(bytes.data(), 0, bytes.bytes(), ex.stream()));
  EXPECT_THROW(rb.post(bytes.data(), gpu::ReadBack::kBytes + 1), std::logic_error);
  rb.clear();
  const gpu::ReadSlot<std::uint8_t> one = rb.post(bytes.data());
  rb.wait();
  EXPECT_THROW((void)rb.value(one, 1), std::logic_error);
  // one launch brings at most kMaxEntries values back
  rb.clear();
  for (int i = 0; i < gpu::ReadBack::kMaxEntries; ++i) (void)rb.post(bytes.data() + i);
  EXPECT_THROW((void)rb.post(bytes.data()), std::logic_error);
  rb.wait();
}

TEST(CudaExecutor, TheReadBackBringsBackOddSizesAtTheirOffsetsAndOnlyWhatWasPostedSinceTheLastClear) {
  FARLIO_REQUIRE_GPU();
  gpu::CudaExecutor ex;
  constexpr std::size_t kN = 37;  // not a multiple of any word
  std::vector<std::uint8_t> host(kN);
  for (std::size_t i = 0; i < kN; ++i) host[i] = static_cast<std::uint8_t>(3 * i + 1);
  gpu::DeviceBuffer<std::uint8_t> bytes(kN, "bytes");
  bytes.upload(host.data(), kN, ex.stream(), "bytes");
  gpu::DeviceBuffer<double> value(1, "value");
  const double pi = 3.141592653589793;
  value.upload(&pi, 1, ex.stream(), "value");
  gpu::ReadBack& rb = ex.read_back();
  rb.clear();
  (void)rb.post(value.data());  // dropped by the clear below: never brought back
  rb.clear();
  const gpu::ReadSlot<std::uint8_t> odd = rb.post(bytes.data() + 1, kN - 1);
  const gpu::ReadSlot<double> d = rb.post(value.data());
  rb.wait();
  for (std::size_t i = 1; i < kN; ++i) EXPECT_EQ(rb.value(odd, i - 1), host[i]) << i;
  EXPECT_EQ(rb.value(d), pi);
  rb.wait();  // nothing posted: only the synchronisation
  EXPECT_EQ(rb.value(d), pi);
}
