# Compiler settings shared by every target of the project.

if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  # Only a default for single-config generators; an explicit choice is never overridden.
  set(CMAKE_BUILD_TYPE RelWithDebInfo CACHE STRING "Build type" FORCE)
endif()

find_program(CCACHE_PROGRAM ccache)
if(CCACHE_PROGRAM)
  set(CMAKE_CXX_COMPILER_LAUNCHER ${CCACHE_PROGRAM})
  set(CMAKE_C_COMPILER_LAUNCHER ${CCACHE_PROGRAM})
  set(CMAKE_CUDA_COMPILER_LAUNCHER ${CCACHE_PROGRAM})
endif()

# Warnings as errors on the project's own code (never on third-party headers, which are
# included as SYSTEM through their imported targets).
function(featsense_warnings target)
  target_compile_options(${target} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
      -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual -Wnull-dereference
      -Wformat=2 -Wimplicit-fallthrough -Werror>
    $<$<COMPILE_LANGUAGE:CUDA>:-Werror=all-warnings -Xcompiler=-Wall,-Wextra,-Werror>)
  # GCC 12 at -O3 (Release) reports out-of-bounds copies inside std::vector's own code that
  # cannot happen (GCC bug 107852 and relatives): shown, but not fatal.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12)
    target_compile_options(${target} PRIVATE
      $<$<COMPILE_LANGUAGE:CXX>:-Wno-error=array-bounds -Wno-error=stringop-overflow>)
  endif()
endfunction()

string(TOLOWER "${FEATSENSE_SANITIZE}" featsense_sanitize)
if(featsense_sanitize STREQUAL "thread")
  # ThreadSanitizer: the pipeline's threads and queues (docs/LIBRARY.md says how to run it).
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
elseif(featsense_sanitize MATCHES "^(on|address|true|1)$")
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
elseif(NOT featsense_sanitize MATCHES "^(off|false|0|)$")
  message(FATAL_ERROR "FEATSENSE_SANITIZE=${FEATSENSE_SANITIZE}: expected OFF, address or thread")
endif()

if(FEATSENSE_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "FEATSENSE_FUZZ needs clang (CC=clang CXX=clang++)")
  endif()
  # The whole project is instrumented for coverage; only the fuzz targets link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
