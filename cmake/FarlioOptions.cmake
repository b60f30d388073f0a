# Warnings and sanitizers, applied per target through farlio_set_options(target).
add_library(farlio_options INTERFACE)
target_compile_options(farlio_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor>)
if(FARLIO_SANITIZE)
  target_compile_options(farlio_options INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-fsanitize=${FARLIO_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all>)
  target_link_options(farlio_options INTERFACE -fsanitize=${FARLIO_SANITIZE})
endif()
if(FARLIO_BUILD_FUZZERS)
  # Coverage feedback for libFuzzer in every library the fuzz targets link (fuzz/CMakeLists.txt).
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "FARLIO_BUILD_FUZZERS needs clang (libFuzzer): configure with "
                        "-DCMAKE_CXX_COMPILER=clang++-14, as scripts/fuzz.sh does")
  endif()
  target_compile_options(farlio_options INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-fsanitize=fuzzer-no-link>)
endif()
