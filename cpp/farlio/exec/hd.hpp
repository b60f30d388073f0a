#pragma once
// FARLIO_HD marks a function that runs on the host and, under nvcc, on the device. Kernel
// bodies (per-point functions) are written once with it and run by the CPU executor (TBB) or a
// CUDA launch (cpp/farlio/cuda/).
#if defined(__CUDACC__)
#define FARLIO_HD __host__ __device__
#else
#define FARLIO_HD
#endif

#if defined(__CUDA_ARCH__)
#define FARLIO_ON_DEVICE 1
#endif
