# Install, export and packaging rules (issue 24), kept in this one file so that the library
# folders hold no install logic. Included from the top-level CMakeLists.txt after every target
# exists. The install rules need SPHEREKIT_INSTALL (on by default only for the top-level project).
#
#   cmake --install build --prefix P     P/bin/spherekit, P/lib/libspherekit_*.a, P/include/spherekit/,
#                                        P/lib/cmake/SphereKit/ (find_package(SphereKit) -> SphereKit::*),
#                                        P/lib/pkgconfig/spherekit.pc, the Python module
#   cpack --config build/CPackConfig.cmake   spherekit_<version>_amd64.deb (program + Python module)
#                                            and spherekit-dev_<version>_amd64.deb (headers, libraries,
#                                            CMake and pkg-config files)
#
# The libraries are installed static (PIC). Their C++ API passes Eigen matrices and option
# structs that change between 0.x versions, so a shared library would promise an ABI we do not
# keep; the program and the Python module are then self-contained, and Draco stays linked
# statically after tinygltf as ECOSYSTEM.md §1.4 requires (a libspherekit_convert.so would
# re-export Draco's copy of the tinygltf symbols). The cost: a downstream link needs the
# private dependencies too, which SphereKitConfig.cmake finds (find_dependency) for the
# components asked for, and which spherekit-dev depends on.

# SphereKit::NAME also inside a build that embeds us (add_subdirectory, where the install rules
# are off), so downstream CMake code reads the same either way.
foreach(_spherekit_lib param formats samples convert pipeline)
  if(TARGET spherekit_${_spherekit_lib})
    add_library(SphereKit::${_spherekit_lib} ALIAS spherekit_${_spherekit_lib})
  endif()
endforeach()
if(NOT SPHEREKIT_INSTALL)
  return()
endif()

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SPHEREKIT_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/SphereKit" CACHE STRING
    "Where SphereKitConfig.cmake goes, relative to the install prefix")
mark_as_advanced(SPHEREKIT_INSTALL_CMAKEDIR)

set(_spherekit_components "")
set(_spherekit_component_code "")
# spherekit_export_library(NAME [USES component...] [PACKAGES "find_package args"...]
#                          [HEADERS file... HEADER_DESTINATION subdir])
# Installs target spherekit_NAME as SphereKit::NAME (component NAME of find_package), with the
# public headers of its include/ folder (or the HEADERS listed), and records for the package
# config which components it links (USES) and which packages its link interface needs.
macro(spherekit_export_library name)
  cmake_parse_arguments(_ske "" "HEADER_DESTINATION" "USES;PACKAGES;HEADERS" ${ARGN})
  set(_ske_target spherekit_${name})
  set_target_properties(${_ske_target} PROPERTIES EXPORT_NAME ${name})
  install(TARGETS ${_ske_target} EXPORT SphereKitTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
  if(_ske_HEADERS)
    install(FILES ${_ske_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/${_ske_HEADER_DESTINATION} COMPONENT dev)
    target_include_directories(${_ske_target} INTERFACE
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/${_ske_HEADER_DESTINATION}>)
  else()
    get_target_property(_ske_dir ${_ske_target} SOURCE_DIR)
    install(DIRECTORY ${_ske_dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev
            FILES_MATCHING PATTERN "*.h")
  endif()
  target_include_directories(${_ske_target} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  list(APPEND _spherekit_components ${name})
  string(APPEND _spherekit_component_code "set(_SphereKit_uses_${name} ${_ske_USES})\n"
                                          "macro(_SphereKit_find_${name})\n")
  foreach(_ske_package IN LISTS _ske_PACKAGES)
    string(APPEND _spherekit_component_code "  find_dependency(${_ske_package})\n")
  endforeach()
  string(APPEND _spherekit_component_code "endmacro()\n")
endmacro()

# One line per library. The private dependencies are listed because the libraries are static:
# their link interface carries them (as $<LINK_ONLY:...>).
spherekit_export_library(param PACKAGES "Eigen3 3.3 NO_MODULE" Threads OpenMP)
spherekit_export_library(formats USES param PACKAGES "nlohmann_json 3" "draco 1.5 CONFIG" "meshoptimizer CONFIG")
spherekit_export_library(samples USES param formats
  HEADERS ${PROJECT_SOURCE_DIR}/samples/common/sample_collection.h HEADER_DESTINATION spherekit/samples)
spherekit_export_library(convert USES param formats
  PACKAGES "OpenEXR 3.1 CONFIG" "TinyGLTF 2.7 CONFIG" "draco 1.5 CONFIG" "OpenSubdiv 3.5 MODULE" OpenMP ZLIB)
if(TARGET spherekit_pipeline)
  spherekit_export_library(pipeline USES param formats samples convert PACKAGES "nlohmann_json 3")
endif()

# The generated version header (libparam/version.h.in).
install(FILES ${PROJECT_BINARY_DIR}/libparam/include/spherekit/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/spherekit COMPONENT dev)

if(TARGET spherekit)
  install(TARGETS spherekit RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()
# The Python module, where Debian's python3 finds it for the /usr prefix (the package); for other
# prefixes, put PREFIX/lib/python3/dist-packages on PYTHONPATH.
set(SPHEREKIT_PYTHON_INSTALL_DIR "lib/python3/dist-packages" CACHE STRING
    "Where the Python module goes, relative to the install prefix")
if(TARGET spherekit_python)
  install(TARGETS spherekit_python LIBRARY DESTINATION ${SPHEREKIT_PYTHON_INSTALL_DIR} COMPONENT runtime)
endif()

# --- find_package(SphereKit) ---------------------------------------------------------------
install(EXPORT SphereKitTargets NAMESPACE SphereKit:: DESTINATION ${SPHEREKIT_INSTALL_CMAKEDIR} COMPONENT dev)
file(WRITE ${PROJECT_BINARY_DIR}/SphereKitComponents.cmake
     "# Generated by cmake/SpherekitInstall.cmake: per component, the components it links and\n"
     "# the packages its link interface needs.\n"
     "set(_SphereKit_all_components ${_spherekit_components})\n"
     "${_spherekit_component_code}")
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/SphereKitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/SphereKitConfig.cmake INSTALL_DESTINATION ${SPHEREKIT_INSTALL_CMAKEDIR})
# 0.x: a minor version may break the API, so only the same major.minor is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/SphereKitConfigVersion.cmake
  VERSION ${SphereKit_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/SphereKitConfig.cmake ${PROJECT_BINARY_DIR}/SphereKitConfigVersion.cmake
              ${PROJECT_BINARY_DIR}/SphereKitComponents.cmake
              # Debian 12's OpenSubdiv config is broken (ECOSYSTEM.md §1.1): convert's link
              # interface names OpenSubdiv::osdCPU from our own module.
              ${CMAKE_CURRENT_LIST_DIR}/FindOpenSubdiv.cmake
        DESTINATION ${SPHEREKIT_INSTALL_CMAKEDIR} COMPONENT dev)

# --- pkg-config ----------------------------------------------------------------------------
# Relocatable: the prefix is found from the .pc file's own place (cmake --install --prefix).
file(RELATIVE_PATH _spherekit_pc_to_prefix "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
set(SPHEREKIT_PC_PREFIX "\${pcfiledir}/${_spherekit_pc_to_prefix}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/spherekit.pc.in ${PROJECT_BINARY_DIR}/spherekit.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/spherekit.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)

# --- Debian packages (CPack) ---------------------------------------------------------------
# Two packages from one `cpack`: spherekit (program + Python module; its library dependencies
# found by dpkg-shlibdeps, so `apt-get install ./spherekit_<version>_amd64.deb` pulls them in)
# and spherekit-dev (headers, static libraries, CMake and pkg-config files; it depends on the
# -dev packages the static link interface needs).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME spherekit)
set(CPACK_PACKAGE_VERSION ${SphereKit_VERSION})
set(CPACK_PACKAGE_CONTACT "SphereKit maintainers <spherekit@invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "bijective spherical parameterization of genus-0 meshes")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME spherekit)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "bijective spherical parameterization of genus-0 meshes (program and Python module)
Maps closed or holed genus-0 triangle meshes bijectively onto the unit sphere (Praun & Hoppe
2003), maps collections consistently (Asirvatham, Praun, Hoppe 2005) and converts them to
geometry images, subdivision cages and Draco glTF levels of detail.")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME spherekit-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_COMPONENT_DEV_DESCRIPTION "SphereKit C++ libraries (static), headers, CMake package and pkg-config file
find_package(SphereKit) gives SphereKit::param, ::formats, ::samples and ::convert.")
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "g++, libeigen3-dev, nlohmann-json3-dev, libopenexr-dev, libtinygltf-dev, libdraco-dev, libmeshoptimizer-dev, libosd-dev, libstb-dev, zlib1g-dev")
if(TARGET spherekit_python)
  # dpkg-shlibdeps cannot see these: an extension module does not link libpython.
  string(REGEX REPLACE "^([0-9]+)\\.([0-9]+)$" "\\1" _spherekit_py_major "${SPHEREKIT_PYTHON_VERSION}")
  string(REGEX REPLACE "^([0-9]+)\\.([0-9]+)$" "\\2" _spherekit_py_minor "${SPHEREKIT_PYTHON_VERSION}")
  math(EXPR _spherekit_py_next "${_spherekit_py_minor} + 1")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS
      "python3 (>= ${SPHEREKIT_PYTHON_VERSION}), python3 (<< ${_spherekit_py_major}.${_spherekit_py_next}), python3-numpy")
endif()
include(CPack)
