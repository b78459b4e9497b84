# `cmake --install`: libsinew as a library package (README.md "Linking"), in two install
# components (`cmake --install <build> --component <name>`; the tools are a third,
# cmake/install_tools.cmake):
#   runtime      <libdir>/libsinew.so.<major>.<minor>.<patch>, libsinew.so.<major>
#   development  <libdir>/libsinew.so (the link-time name), <libdir>/libsinew.a
#                <includedir>/sinew/*.h      the public headers (plugin_api/include/sinew)
#                <libdir>/pkgconfig/sinew.pc Libs.private/Requires.private: the static link
#                <libdir>/cmake/sinew/       find_package(sinew CONFIG): sinew::sinew
#                                            (shared), sinew::sinew_static (when its deps
#                                            are found)
# Only the runtime and its headers: nothing of precompute/ (LAPACKE, OpenBLAS, CHOLMOD,
# assimp, cJSON) is needed to use the package. tests/install.cmake checks all of this
# from an install into a scratch prefix.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SINEW_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/sinew)

install(TARGETS sinew EXPORT sinewTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
          NAMELINK_COMPONENT development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# A separate export set: its link dependencies (embree, libccd) are looked for only by
# the static part of sinewConfig.cmake, so a shared-only host needs none of their
# development files.
install(TARGETS sinew_static EXPORT sinewStaticTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/plugin_api/include/sinew
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT development
  FILES_MATCHING PATTERN "*.h")

install(EXPORT sinewTargets NAMESPACE sinew:: DESTINATION ${SINEW_CMAKE_DIR}
  COMPONENT development)
install(EXPORT sinewStaticTargets NAMESPACE sinew:: DESTINATION ${SINEW_CMAKE_DIR}
  COMPONENT development)
configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/sinewConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/sinewConfig.cmake INSTALL_DESTINATION ${SINEW_CMAKE_DIR})
# The ABI changes only with the major version (sinew_base.h, the SONAME).
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/sinewConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/sinewConfig.cmake
  ${CMAKE_CURRENT_BINARY_DIR}/sinewConfigVersion.cmake
  DESTINATION ${SINEW_CMAKE_DIR} COMPONENT development)

# sinew.pc, relocatable: prefix is found from the .pc file's own folder (${pcfiledir},
# understood by pkg-config and pkgconf), so `cmake --install --prefix P` and DESTDIR work.
set(SINEW_PC_DIR ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${SINEW_PC_DIR}")
  set(SINEW_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH rel "/p/${SINEW_PC_DIR}" "/p")
  string(REGEX REPLACE "/$" "" rel "${rel}")
  set(SINEW_PC_PREFIX "\${pcfiledir}/${rel}")
endif()
foreach(d LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${d}}")
    set(SINEW_PC_${d} "${CMAKE_INSTALL_${d}}")
  else()
    set(SINEW_PC_${d} "\${prefix}/${CMAKE_INSTALL_${d}}")
  endif()
endforeach()
# Embree has no .pc file: name its library directly (-L only outside the linker's own
# search path), from the location its CMake package gives.
set(SINEW_PC_EMBREE "-lembree3")
get_target_property(cfgs embree IMPORTED_CONFIGURATIONS)
foreach(c ${cfgs} NOCONFIG)
  get_target_property(loc embree IMPORTED_LOCATION_${c})
  if(loc)
    get_filename_component(dir "${loc}" DIRECTORY)
    get_filename_component(name "${loc}" NAME)
    string(REGEX REPLACE "^lib([^.]+)\\..*$" "\\1" name "${name}")
    set(SINEW_PC_EMBREE "-l${name}")
    if(NOT dir IN_LIST CMAKE_C_IMPLICIT_LINK_DIRECTORIES)
      set(SINEW_PC_EMBREE "-L${dir} ${SINEW_PC_EMBREE}")
    endif()
    break()
  endif()
endforeach()
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/sinew.pc.in ${CMAKE_CURRENT_BINARY_DIR}/sinew.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/sinew.pc DESTINATION ${SINEW_PC_DIR}
  COMPONENT development)
