# bd_set_warnings(target): the warning set for our own code; errors when BD_WERROR is on.
function(bd_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                         -Wno-sign-conversion $<$<BOOL:${BD_WERROR}>:-Werror>)
  # GCC 12 at -O3 reports -Wrestrict inside libstdc++'s inlined std::string concatenation
  # (GCC bug 105329, fixed in GCC 13): a false positive in the library, not in our code
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  # GCC's manual (-fsanitize=address): "sanitizers tend to increase the rate of false positive
  # warnings, most notably those around -Wmaybe-uninitialized"; GCC 12 reports it inside
  # libstdc++'s <regex> (std::function in _StateT). The unsanitized builds keep the check.
  if(BD_SANITIZE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
  endif()
endfunction()
