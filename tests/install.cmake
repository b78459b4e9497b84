# Packaging tests: `cmake --install` into a scratch prefix, then the sample host
# (samples/host) built against that prefix with find_package(sinew) and with pkg-config,
# shared and static, and run on a small blob baked by the build's sinew-bake
# (tests/install/check_install.sh). In sanitizer builds the hosts are built with the same
# -fsanitize: a sanitized libsinew cannot serve a plain host (the shared one aborts, the
# sanitizer runtime not being loaded first; the static one does not link).
# SINEW_SANITIZE may be OFF (its option() default) as well as empty: as the top level does.
set(sw_install_sanitize "")
if(SINEW_SANITIZE)
  set(sw_install_sanitize "${SINEW_SANITIZE}")
endif()
foreach(mode find_package pkg_config)
  add_test(NAME install_${mode}
    COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/check_install.sh ${mode} ${CMAKE_BINARY_DIR}
            ${CMAKE_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/install_${mode}
            ${CMAKE_C_COMPILER} "${sw_install_sanitize}" $<TARGET_FILE:sinew-bake>)
  set_tests_properties(install_${mode} PROPERTIES LABELS install TIMEOUT 120
    RESOURCE_LOCK sinew_install_manifest) # both write <build>/install_manifest.txt
endforeach()

# The pipeline's install: `cmake --install --component tools` puts every tool the build
# made, and nothing else, into a scratch prefix, and the tools run from there
# (tests/install/check_install_tools.sh).
set(sw_built_tools)
foreach(tool ${SINEW_INSTALL_TOOLS})
  if(TARGET ${tool})
    list(APPEND sw_built_tools ${tool})
  endif()
endforeach()
add_test(NAME install_tools
  COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/check_install_tools.sh ${CMAKE_BINARY_DIR}
          ${CMAKE_CURRENT_BINARY_DIR}/install_tools ${sw_built_tools})
set_tests_properties(install_tools PROPERTIES LABELS install TIMEOUT 300)

# The engine's build: a fresh copy of the source configured with -DSINEW_BUILD_BAKE=OFF
# looks for none of the bake's packages, builds the runtime alone, installs its runtime
# and development components, and the sample host built against them steps a blob
# (tests/install/check_runtime_only.sh). Its own build tree, unsanitized: the host is
# plain. About 20 s of CPU (the runtime compiled once more).
add_test(NAME install_runtime_only
  COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/check_runtime_only.sh ${CMAKE_SOURCE_DIR}
          ${CMAKE_CURRENT_BINARY_DIR}/install_runtime_only ${CMAKE_C_COMPILER}
          ${CMAKE_CXX_COMPILER} ${SINEW_WERROR} $<TARGET_FILE:sinew-bake>)
set_tests_properties(install_runtime_only PROPERTIES LABELS install TIMEOUT 600)
