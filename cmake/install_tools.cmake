# `cmake --install <build> --component tools`: the command-line tools a pipeline runs,
# into <bindir>. They link the runtime and the bake statically; what they load at run
# time is the system's (Embree, libccd, assimp, CHOLMOD, OpenBLAS, LAPACKE, libcjson).
# Their install RPATH keeps the link folders outside the system's own (a dependency found
# in /opt is found there again from the prefix), and a tool that links the shared
# libsinew gets <prefix>/<libdir> too. Only then: an install RPATH longer than the build
# tree's makes CMake pad the build tree's with empty entries, which the loader reads as
# the current folder. A tool is installed when it is built: the list names targets, not
# files, so it holds wherever tools/ keeps their sources.
include(GNUInstallDirs)

set(SINEW_INSTALL_TOOLS sinew-bake sinew-bench sinew-fullsim sinew-inspect sinew-render
  sinew-soak sinew-invariance sinew-view)
file(RELATIVE_PATH sw_bin_to_lib ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_LIBDIR})
foreach(tool ${SINEW_INSTALL_TOOLS})
  if(TARGET ${tool})
    set_target_properties(${tool} PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
    get_target_property(sw_libs ${tool} LINK_LIBRARIES)
    if("sinew" IN_LIST sw_libs)
      set_target_properties(${tool} PROPERTIES INSTALL_RPATH "$ORIGIN/${sw_bin_to_lib}")
    endif()
    install(TARGETS ${tool} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
  endif()
endforeach()
unset(sw_bin_to_lib)
unset(sw_libs)
