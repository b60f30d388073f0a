# Warnings and sanitizers, applied per target through farlio_set_options(target).
add_library(farlio_options INTERFACE)
target_compile_options(farlio_options INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor>)
if(FARLIO_SANITIZE)
  target_compile_options(farlio_options INTERFACE
    $<$<COMPILE_LANGUAGE:CXX>:-fsanitize=${FARLIO_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all>)
  target_link_options(farlio_options INTERFACE -fsanitize=${FARLIO_SANITIZE})
endif()
