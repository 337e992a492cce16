# SPDX-License-Identifier: GPL-2.0-or-later
# Instrumented builds, each in its own build folder:
#
#   I20_SANITIZE=ON  AddressSanitizer + UndefinedBehaviorSanitizer on everything (the
#                    whole test suite, and the programs the CLI tests start). Any report
#                    aborts the process: -fno-sanitize-recover=all, and scripts/sanitize
#                    sets ASAN_OPTIONS/UBSAN_OPTIONS so the test fails.
#   I20_FUZZ=ON      libFuzzer targets in fuzz/ (clang only): the libraries get coverage
#                    instrumentation plus ASan/UBSan; the targets link the fuzzer driver.
option(I20_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(I20_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang)" OFF)

set(I20_SANITIZER_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)

if(I20_SANITIZE)
  add_compile_options(${I20_SANITIZER_FLAGS})
  # The instrumentation defeats GCC's flow analysis: -Wmaybe-uninitialized then fires
  # inside libstdc++ (std::regex, std::function) on code the normal builds compile cleanly.
  # The uninitialised reads themselves are what this build exists to catch at run time.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    add_compile_options(-Wno-maybe-uninitialized)
  endif()
  add_link_options(-fsanitize=address,undefined -fno-sanitize-recover=all)
endif()

if(I20_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "I20_FUZZ needs clang (libFuzzer): configure with CXX=clang++")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link ${I20_SANITIZER_FLAGS})
  add_link_options(-fsanitize=address,undefined -fno-sanitize-recover=all)
endif()
