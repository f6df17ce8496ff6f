# ssx_set_warnings(target): the project's warning set; errors when SSX_WARNINGS_AS_ERRORS is on (CI).
function(ssx_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(SSX_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
