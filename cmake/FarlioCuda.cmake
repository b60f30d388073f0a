# The CUDA backend switch. AUTO enables CUDA where nvcc is found (on PATH, CUDACXX, or the
# toolkit's default /usr/local/cuda) and compiles it for the GPUs of this machine; with nvcc but no
# GPU it is left out (one status line says so), which keeps the first build short. ON compiles it
# for FARLIO_CUDA_ARCHITECTURES (environment) or the default list; so does AUTO when
# CMAKE_CUDA_ARCHITECTURES or FARLIO_CUDA_ARCHITECTURES asks for architectures (CI compiles two on
# a machine without a GPU: scripts/test.sh). A build without CUDA works everywhere.
set(FARLIO_WITH_CUDA OFF)
# Turing, Ampere (incl. A5000), Jetson Orin, Ada, Hopper.
set(FARLIO_DEFAULT_CUDA_ARCHITECTURES 75 80 86 87 89 90)

# Whether this machine has a GPU: the CUDA toolkit's device query (`__nvcc_device_query`) prints the
# compute capabilities of the devices the driver reaches, and fails without a driver or a device.
function(farlio_gpu_present out)
  get_filename_component(bin "${CMAKE_CUDA_COMPILER}" DIRECTORY)
  set(present OFF)
  if(EXISTS "${bin}/__nvcc_device_query")
    execute_process(COMMAND "${bin}/__nvcc_device_query" RESULT_VARIABLE rc OUTPUT_VARIABLE found ERROR_QUIET
                    OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(rc EQUAL 0 AND NOT found STREQUAL "")
      set(present ON)
    endif()
  endif()
  set(${out} ${present} PARENT_SCOPE)
endfunction()

if(NOT FARLIO_CUDA STREQUAL "OFF")
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc CACHE FILEPATH "nvcc")
  endif()
  include(CheckLanguage)
  check_language(CUDA)
  set(farlio_cuda_wanted OFF)
  if(CMAKE_CUDA_COMPILER)
    set(farlio_cuda_wanted ON)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      if(DEFINED ENV{FARLIO_CUDA_ARCHITECTURES})
        set(CMAKE_CUDA_ARCHITECTURES "$ENV{FARLIO_CUDA_ARCHITECTURES}" CACHE STRING "CUDA architectures")
      elseif(FARLIO_CUDA STREQUAL "ON")
        set(CMAKE_CUDA_ARCHITECTURES ${FARLIO_DEFAULT_CUDA_ARCHITECTURES} CACHE STRING "CUDA architectures")
      else()
        farlio_gpu_present(gpu)
        if(gpu)
          set(CMAKE_CUDA_ARCHITECTURES native CACHE STRING "CUDA architectures (the GPUs of this machine)")
        else()
          message(STATUS "farlio: nvcc found but no GPU on this machine: the CUDA backend is not built "
                         "(FARLIO_CUDA=ON, or FARLIO_CUDA_ARCHITECTURES=\"75;90\", builds it anyway)")
          set(farlio_cuda_wanted OFF)
        endif()
      endif()
    endif()
  elseif(FARLIO_CUDA STREQUAL "ON")
    message(FATAL_ERROR "FARLIO_CUDA=ON but no CUDA compiler (nvcc) was found; set CUDACXX or use FARLIO_CUDA=AUTO")
  endif()
  if(farlio_cuda_wanted)
    enable_language(CUDA)
    # The shared headers need C++20 in CUDA code too. CMake 3.25 knows no CUDA20 dialect for
    # nvcc (and falls back to CXX_STANDARD 20, which it then rejects), so CUDA targets ask for
    # CUDA17 and that dialect's flag is nvcc's -std=c++20 (accepted since CUDA 12).
    set(CMAKE_CUDA_STANDARD 17)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    set(CMAKE_CUDA17_STANDARD_COMPILE_OPTION "-std=c++20")
    set(CMAKE_CUDA17_EXTENSION_COMPILE_OPTION "-std=c++20")
    set(FARLIO_WITH_CUDA ON)
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
