# Warnings, determinism and sanitizer flags shared by every cadclash target.

# Contracting a*b+c into an FMA changes rounding, which would break the error bounds of the
# floating-point filters and make results depend on the compiler's choice.
add_compile_options(-ffp-contract=off)

if(CADCLASH_SANITIZE)
  string(REPLACE "," ";" _cadclash_sanitizers "${CADCLASH_SANITIZE}")
  foreach(_s IN LISTS _cadclash_sanitizers)
    if(NOT _s MATCHES "^(address|undefined|thread|leak)$")
      message(FATAL_ERROR "CADCLASH_SANITIZE: unknown sanitizer '${_s}'")
    endif()
  endforeach()
  add_compile_options(-fsanitize=${CADCLASH_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${CADCLASH_SANITIZE})
endif()

# Applies the project's warning set to one of its own targets.
function(cadclash_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
  if(CADCLASH_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
