# One place for warning flags, applied per target (never through global CMAKE_CXX_FLAGS).
function(spherekit_set_warnings tgt)
  target_compile_options(${tgt} PRIVATE -Wall -Wextra -Wno-maybe-uninitialized -Wno-unused-parameter)
  if(SPHEREKIT_WERROR)
    target_compile_options(${tgt} PRIVATE -Werror)
  endif()
endfunction()
