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
      # Turing, Ampere (incl. A5000), Jetson Orin, Ada, Hopper.
      set(CMAKE_CUDA_ARCHITECTURES 75 80 86 87 89 90 CACHE STRING "CUDA architectures")
    endif()
    enable_language(CUDA)
    set(CMAKE_CUDA_STANDARD 17)  # CMake 3.25 knows no CUDA20 dialect for nvcc 13
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    set(FARLIO_WITH_CUDA ON)
  elseif(FARLIO_CUDA STREQUAL "ON")
    message(FATAL_ERROR "FARLIO_CUDA=ON but no CUDA compiler (nvcc) was found; set CUDACXX or use FARLIO_CUDA=AUTO")
  endif()
endif()
message(STATUS "farlio: CUDA backend ${FARLIO_WITH_CUDA}")
