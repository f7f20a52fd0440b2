# Project-wide compile settings applied through one interface target.
add_library(bw_build_options INTERFACE)
target_compile_options(bw_build_options INTERFACE
  -Wall -Wextra
  # note: no fused multiply-add, so results match across builds and machines.
  -ffp-contract=off)
if(BW_SANITIZE STREQUAL "address")
  target_compile_options(bw_build_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(bw_build_options INTERFACE -fsanitize=address,undefined)
elseif(BW_SANITIZE STREQUAL "thread")
  target_compile_options(bw_build_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(bw_build_options INTERFACE -fsanitize=thread)
elseif(NOT BW_SANITIZE STREQUAL "")
  message(FATAL_ERROR "BW_SANITIZE must be empty, address or thread (got '${BW_SANITIZE}')")
endif()
# note: sanitizer builds (RelWithDebInfo) keep line tables only (-g1, after the config's -g):
# their reports still name function, file and line, and a heavy file compiles a third faster
# (world.cpp under ASan 59 -> 38 s, its object 21 -> 6 MB): CI builds the tree three times so.
# BW_SANITIZED lets the few tests that run a scene for a minute of simulated time run a shorter
# stretch of the same code under a sanitizer (the release run checks the full minute's physics;
# ASan's part is the memory, and the minute took 7.5 of the CI's ASan stage's 13 minutes).
if(NOT BW_SANITIZE STREQUAL "")
  target_compile_options(bw_build_options INTERFACE -g1)
  target_compile_definitions(bw_build_options INTERFACE BW_SANITIZED)
endif()
# The fuzz preset: every library instrumented for libFuzzer's coverage feedback (the targets in
# tests/fuzz link the fuzzer runtime itself). clang only.
if(BW_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "BW_FUZZ needs clang (libFuzzer): use the fuzz preset")
  endif()
  target_compile_options(bw_build_options INTERFACE -fsanitize=fuzzer-no-link)
endif()
# note: the 24 axis rotations' composition table is computed at compile time; clang's default
# constexpr step limit stops short of it.
if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  target_compile_options(bw_build_options INTERFACE -fconstexpr-steps=50000000)
endif()
# BW_ASSERT (collision/core/assert.h) is checked in debug and under the sanitizers, never in the
# release build the figures come from.
if(CMAKE_BUILD_TYPE STREQUAL "Debug" OR NOT BW_SANITIZE STREQUAL "")
  target_compile_definitions(bw_build_options INTERFACE BW_ENABLE_ASSERTS)
endif()
add_library(bw::build_options ALIAS bw_build_options)

# bw_add_module(NAME SOURCES... DEPS ...): one static library target bw::NAME per module.
function(bw_add_module name)
  cmake_parse_arguments(M "" "" "SOURCES;DEPS" ${ARGN})
  add_library(bw_${name} STATIC ${M_SOURCES})
  add_library(bw::${name} ALIAS bw_${name})
  target_include_directories(bw_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(bw_${name} PUBLIC bw::build_options ${M_DEPS})
endfunction()
