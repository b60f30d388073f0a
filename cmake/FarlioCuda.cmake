# The CUDA backend switch. AUTO enables CUDA where nvcc is found (on PATH, CUDACXX, or the
# toolkit's default /usr/local/cuda); a build without CUDA works everywhere.
set(FARLIO_WITH_CUDA OFF)
if(NOT FARLIO_CUDA STREQUAL "OFF")
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc CACHE FILEPATH "nvcc")
  endif()
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      if(DEFINED ENV{FARLIO_CUDA_ARCHITECTURES})
        # a build that only needs to prove the code compiles (CI: scripts/test.sh) picks fewer
        set(CMAKE_CUDA_ARCHITECTURES "$ENV{FARLIO_CUDA_ARCHITECTURES}" CACHE STRING "CUDA architectures")
      else()
        # Turing, Ampere (incl. A5000), Jetson Orin, Ada, Hopper.
        set(CMAKE_CUDA_ARCHITECTURES 75 80 86 87 89 90 CACHE STRING "CUDA architectures")
      endif()
    endif()
    enable_language(CUDA)
    # The shared headers need C++20 in CUDA code too. CMake 3.25 knows no CUDA20 dialect for
    # nvcc (and falls back to CXX_STANDARD 20, which it then rejects), so CUDA targets ask for
    # CUDA17 and that dialect's flag is nvcc's -std=c++20 (accepted since CUDA 12).
    set(CMAKE_CUDA_STANDARD 17)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    set(CMAKE_CUDA17_STANDARD_COMPILE_OPTION "-std=c++20")
    set(CMAKE_CUDA17_EXTENSION_COMPILE_OPTION "-std=c++20")
    set(FARLIO_WITH_CUDA ON)
  elseif(FARLIO_CUDA STREQUAL "ON")
    message(FATAL_ERROR "FARLIO_CUDA=ON but no CUDA compiler (nvcc) was found; set CUDACXX or use FARLIO_CUDA=AUTO")
  endif()
endif()
message(STATUS "farlio: CUDA backend ${FARLIO_WITH_CUDA}")

# Flags of every CUDA translation unit (applied by target_link_libraries(... farlio_cuda_options)):
# - Eigen in device code: constexpr host functions callable from the device, and a warning about
#   its defaulted __host__ __device__ members silenced.
# - __device__ lambdas as kernel bodies (CudaExecutor::for_each).
# - no fused multiply-add contraction, so the shared bodies round as on the host (x86-64 without
#   FMA): the CPU and GPU maps then hold the same points (docs/cuda.md).
if(FARLIO_WITH_CUDA)
  add_library(farlio_cuda_options INTERFACE)
  target_compile_options(farlio_cuda_options INTERFACE
    $<$<COMPILE_LANGUAGE:CUDA>:--expt-relaxed-constexpr --extended-lambda -diag-suppress=20012 --fmad=false>)
endif()
