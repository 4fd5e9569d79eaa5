# Warnings for our own targets; third-party headers come in as SYSTEM includes.
function(diefill_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow=local -Wno-unknown-pragmas)
  if(DIEFILL_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
