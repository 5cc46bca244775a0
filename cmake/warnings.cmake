# bd_set_warnings(target): the warning set for our own code; errors when BD_WERROR is on.
function(bd_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                         -Wno-sign-conversion $<$<BOOL:${BD_WERROR}>:-Werror>)
endfunction()
