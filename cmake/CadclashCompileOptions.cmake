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

# Declares module `name`: library cadclash_<name>, alias cadclash::<name> (the export name too), its
# public headers in <module>/include, the warning set. Sources and links stay in the module's file.
function(cadclash_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(cadclash_${name} ${ARG_SOURCES})
  add_library(cadclash::${name} ALIAS cadclash_${name})
  set_target_properties(cadclash_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME cadclash_${name})
  target_include_directories(cadclash_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
  cadclash_target_warnings(cadclash_${name})
endfunction()
