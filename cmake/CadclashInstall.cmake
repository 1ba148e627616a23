# Installs the five libraries, their headers, the cadclash tool, a CMake package
# (find_package(cadclash [COMPONENTS collide report tessellate import export]) → cadclash::<component>)
# and cadclash.pc.
#
# Each library gets its own export file so that a consumer asking only for `collide` needs neither
# OpenCASCADE nor assimp. The libraries are static by default: their PRIVATE dependencies are exported
# as $<LINK_ONLY:...> (CGAL's GMP/MPFR, assimp, OCCT toolkits), so the package config finds them too.
include_guard(GLOBAL)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

option(CADCLASH_INSTALL "Generate the install rules and the cadclash CMake package" ${cadclash_top_level})
if(NOT CADCLASH_INSTALL)
  return()
endif()

set(CADCLASH_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/cadclash" CACHE STRING
    "Where cadclashConfig.cmake is installed, relative to the prefix")
mark_as_advanced(CADCLASH_INSTALL_CMAKEDIR)

# One export file per library. cadclash_triangle_exact is an object library linked privately into
# cadclash_collide: its objects are already inside the archive, but the export must name it to carry
# its link-only CGAL dependency.
function(cadclash_install_component component)
  install(TARGETS ${ARGN} EXPORT cadclash-${component}-targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT cadclash_development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT cadclash_runtime
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cadclash_runtime
    OBJECTS DESTINATION ${CMAKE_INSTALL_LIBDIR}/cadclash-objects COMPONENT cadclash_development)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${component}/include/
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT cadclash_development)
  install(EXPORT cadclash-${component}-targets NAMESPACE cadclash::
    DESTINATION ${CADCLASH_INSTALL_CMAKEDIR} COMPONENT cadclash_development)
endfunction()
cadclash_install_component(collide cadclash_collide cadclash_triangle_exact)
cadclash_install_component(report cadclash_report)
cadclash_install_component(tessellate cadclash_tessellate)
cadclash_install_component(import cadclash_import)
cadclash_install_component(export cadclash_export)

if(TARGET cadclash)
  install(TARGETS cadclash RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cadclash_runtime)
endif()

# The config re-finds exactly what the exported link interfaces name; versions as the build required.
set(CADCLASH_STATIC_LIBS OFF)
get_target_property(_type cadclash_collide TYPE)
if(_type STREQUAL "STATIC_LIBRARY")
  set(CADCLASH_STATIC_LIBS ON)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/cadclashConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cadclashConfig.cmake
  INSTALL_DESTINATION ${CADCLASH_INSTALL_CMAKEDIR})
# 0.x: a minor release may break the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cadclashConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cadclashConfig.cmake ${PROJECT_BINARY_DIR}/cadclashConfigVersion.cmake
  DESTINATION ${CADCLASH_INSTALL_CMAKEDIR} COMPONENT cadclash_development)

# pkg-config: one cadclash.pc for all the libraries (static archives need every dependency on the
# link line, so they go to Libs; a shared build moves them to Libs.private). Paths are relative to
# the .pc file so `cmake --install --prefix` elsewhere still works.
file(RELATIVE_PATH _pc_to_prefix "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
string(REGEX REPLACE "/$" "" _pc_to_prefix "${_pc_to_prefix}")
set(CADCLASH_PC_PREFIX "\${pcfiledir}/${_pc_to_prefix}")
set(_occt_libs TKXDEIGES TKIGES TKXDESTEP TKSTEP TKSTEPBase TKXSBase TKXCAF TKCAF TKLCAF TKShHealing TKMesh
  TKTopAlgo TKBRep TKGeomBase TKG3d TKMath TKernel)
list(TRANSFORM _occt_libs PREPEND "-l")
list(JOIN _occt_libs " " _occt_libs)
# The modules find OCCT in their own directory scope; look again here for its library directory.
find_package(OpenCASCADE QUIET)
set(_pc_deps "${_occt_libs} -lcrypto -lmpfr -lgmp -fopenmp -pthread")
if(OpenCASCADE_LIBRARY_DIR AND NOT OpenCASCADE_LIBRARY_DIR IN_LIST CMAKE_CXX_IMPLICIT_LINK_DIRECTORIES)
  set(_pc_deps "-L${OpenCASCADE_LIBRARY_DIR} ${_pc_deps}")
endif()
if(CADCLASH_STATIC_LIBS)
  set(CADCLASH_PC_LIBS "${_pc_deps}")
  set(CADCLASH_PC_LIBS_PRIVATE "")
  set(CADCLASH_PC_REQUIRES "eigen3 assimp")
  set(CADCLASH_PC_REQUIRES_PRIVATE "")
else()
  set(CADCLASH_PC_LIBS "-fopenmp")
  set(CADCLASH_PC_LIBS_PRIVATE "${_pc_deps}")
  set(CADCLASH_PC_REQUIRES "eigen3")
  set(CADCLASH_PC_REQUIRES_PRIVATE "assimp")
endif()
configure_file(${CMAKE_CURRENT_LIST_DIR}/cadclash.pc.in ${PROJECT_BINARY_DIR}/cadclash.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/cadclash.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT cadclash_development)
