# Options for our own targets: warnings (third-party headers come in as SYSTEM includes) and,
# in the sanitizer build, instrumentation.
#
# The sanitizer build (scripts/setup.sh --sanitize) keeps the Release flags and adds to each of
# our targets light optimisation, assertions, AddressSanitizer and UndefinedBehaviorSanitizer.
# -O1, as the sanitizers' own documentation advises: at -O0 the DEM's unit tests alone took
# 7 of the 13 minutes the sanitizer run took (two of them over 200 s each).
# A target declared UNINSTRUMENTED keeps the Release flags: the CGAL wrappers, which hold only
# the library's algorithms instantiated behind mesh/cgal_ops.hpp and take a minute each to
# compile. Their command lines are then the Release tree's, so ccache (paths relative to the
# source tree) hands the sanitizer tree the Release objects instead of compiling them again:
# library code stays uninstrumented, as prebuilt libraries (assimp, Embree, TBB) always are.
function(diefill_target_options target)
  cmake_parse_arguments(T "UNINSTRUMENTED" "" "" ${ARGN})
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow=local -Wno-unknown-pragmas)
  if(DIEFILL_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(DIEFILL_SANITIZE AND NOT T_UNINSTRUMENTED)
    target_compile_options(${target} PRIVATE -O1 -UNDEBUG -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
  endif()
endfunction()
