# ABI tests: what an engine linking libsinew relies on (DESIGN.md §3). Included at the
# end of tests/CMakeLists.txt, so every tests/test_*.c test already exists here.
set(SW_ABI_DIR ${CMAKE_CURRENT_SOURCE_DIR}/abi)
set(SW_ABI_HEADERS ${CMAKE_SOURCE_DIR}/plugin_api/include)

# Hosts compile the public header with their own, often stricter, warnings. These are
# always errors here, whatever SINEW_WERROR says: a warning in the header is a bug.
set(SW_ABI_C_FLAGS -pedantic -Wall -Wextra -Werror -Wstrict-prototypes
    -Wmissing-prototypes -Wshadow -Wconversion -Wsign-conversion -Wundef -Wcast-qual)
set(SW_ABI_CXX_FLAGS -pedantic -Wall -Wextra -Werror -Wshadow -Wconversion
    -Wsign-conversion -Wundef -Wcast-qual)

# A host includes the header with its own macros, not ours: undo the feature-test macro
# the project defines for its own sources (a directory property, so -U after the -D),
# so the header must stand on ISO C alone.
function(sw_abi_pristine target)
  target_compile_options(${target} PRIVATE -U_POSIX_C_SOURCE)
endfunction()

# --- exported symbols and SONAME of the shared library -------------------------------
add_test(NAME abi_exports
  COMMAND sh ${SW_ABI_DIR}/check_exports.sh $<TARGET_FILE:sinew> ${SW_ABI_HEADERS})

# The checker must be able to fail: a stand-in library with one violation of each kind.
add_library(sw_abi_bad_exports SHARED ${SW_ABI_DIR}/bad_exports.c)
target_include_directories(sw_abi_bad_exports PRIVATE ${SW_ABI_HEADERS})
set_target_properties(sw_abi_bad_exports PROPERTIES
  OUTPUT_NAME sinew_bad VERSION 9.0.0 SOVERSION 9 C_VISIBILITY_PRESET hidden)
add_test(NAME abi_exports_rejects_violations
  COMMAND sh ${SW_ABI_DIR}/expect_violations.sh ${SW_ABI_DIR}/check_exports.sh
          $<TARGET_FILE:sw_abi_bad_exports> ${SW_ABI_HEADERS}
          "'sw_leaked_helper' (type T) is not prefixed sinew_"
          "'sinew_shared_counter' is writable data"
          "'sinew_undeclared_helper' is exported but not declared"
          "'sinew_result_string' is declared SINEW_API in a public header but not exported"
          "SONAME is 'libsinew_bad.so.9', expected 'libsinew.so.")

# --- imports of the shared library against the committed allow-list ------------------
# tests/abi/libsinew.imports lists what libsinew.so may import (sanitizer builds add
# their runtimes' entry points); the negative control is a stand-in that imports stdio
# and lock functions it must not.
set(SW_ABI_IMPORTS ${SW_ABI_DIR}/libsinew.imports)
set(SW_ABI_IMPORTS_EXTRA)
if(SINEW_SANITIZE)
  list(APPEND SW_ABI_IMPORTS_EXTRA ${SW_ABI_DIR}/libsinew.imports.sanitize)
endif()
add_test(NAME abi_imports
  COMMAND sh ${SW_ABI_DIR}/check_imports.sh $<TARGET_FILE:sinew> ${SW_ABI_IMPORTS}
          ${SW_ABI_IMPORTS_EXTRA})
add_library(sw_abi_bad_imports SHARED ${SW_ABI_DIR}/bad_imports.c)
target_link_libraries(sw_abi_bad_imports PRIVATE Threads::Threads)
set_target_properties(sw_abi_bad_imports PROPERTIES OUTPUT_NAME sinew_bad_imports)
add_test(NAME abi_imports_rejects_violations
  COMMAND sh ${SW_ABI_DIR}/expect_violations.sh ${SW_ABI_DIR}/check_imports.sh
          $<TARGET_FILE:sw_abi_bad_imports> ${SW_ABI_IMPORTS}
          "'fopen' (not in" "'fclose' (not in" "'pthread_spin_lock' (not in"
          "'pthread_spin_unlock' (not in")

# --- the header in strict C: C99 and C11 against the shared library, C99 static -------
# C_STANDARD on the target overrides the project-wide CMAKE_C_STANDARD 17; the source
# checks __STDC_VERSION__ against SW_ABI_EXPECT_STDC, so a lost override fails the build.
function(sw_abi_c_program name std stdc lib)
  add_executable(${name} ${SW_ABI_DIR}/header_c99.c)
  target_link_libraries(${name} PRIVATE ${lib})
  target_include_directories(${name} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  target_compile_options(${name} PRIVATE ${SW_ABI_C_FLAGS})
  target_compile_definitions(${name} PRIVATE SW_ABI_EXPECT_STDC=${stdc})
  set_target_properties(${name} PROPERTIES
    C_STANDARD ${std} C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
  sw_abi_pristine(${name})
  add_test(NAME ${name} COMMAND ${name})
endfunction()
sw_abi_c_program(abi_header_c99 99 199901L sinew)
sw_abi_c_program(abi_header_c11 11 201112L sinew)
sw_abi_c_program(abi_static_c99 99 199901L sinew_static)

# --- the header in C++11, its struct layout compared with the C compiler's -------------
add_library(sw_abi_layout_c OBJECT ${SW_ABI_DIR}/abi_layout_c.c)
target_include_directories(sw_abi_layout_c PRIVATE ${SW_ABI_HEADERS})
target_compile_options(sw_abi_layout_c PRIVATE ${SW_ABI_C_FLAGS})
set_target_properties(sw_abi_layout_c PROPERTIES
  C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
sw_abi_pristine(sw_abi_layout_c)

add_executable(abi_header_cxx ${SW_ABI_DIR}/header_cxx.cpp $<TARGET_OBJECTS:sw_abi_layout_c>)
target_link_libraries(abi_header_cxx PRIVATE sinew)
target_compile_options(abi_header_cxx PRIVATE ${SW_ABI_CXX_FLAGS})
set_target_properties(abi_header_cxx PROPERTIES
  CXX_STANDARD 11 CXX_STANDARD_REQUIRED ON CXX_EXTENSIONS OFF)
sw_abi_pristine(abi_header_cxx)
add_test(NAME abi_header_cxx COMMAND abi_header_cxx)

# --- a host linked to the shared library, resolved at run time by its SONAME -----------
add_executable(abi_host_soname ${SW_ABI_DIR}/host_soname.c)
target_link_libraries(abi_host_soname PRIVATE sinew ${CMAKE_DL_LIBS})
target_compile_options(abi_host_soname PRIVATE ${SW_ABI_C_FLAGS})
set_target_properties(abi_host_soname PROPERTIES
  C_STANDARD 99 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
add_test(NAME abi_host_soname COMMAND abi_host_soname)

set_tests_properties(abi_exports abi_exports_rejects_violations abi_imports
  abi_imports_rejects_violations abi_header_c99
  abi_header_c11 abi_static_c99 abi_header_cxx abi_host_soname
  PROPERTIES LABELS abi TIMEOUT 60)

# --- threading tests: label "threads", run by the TSan stage of tools/run-tests.sh -----
# Any test whose name says it is about threads, determinism or the pool gets the label,
# so later tests (e.g. a golden-hash determinism test) join the TSan run by name.
get_property(sw_all_tests DIRECTORY PROPERTY TESTS)
foreach(t ${sw_all_tests})
  if(t MATCHES "thread|determinism|pool")
    set_property(TEST ${t} APPEND PROPERTY LABELS threads)
  endif()
endforeach()
if(TEST test_thread_pool)
  set_tests_properties(test_thread_pool PROPERTIES LABELS threads)
endif()

# --- the exported ABI against the committed baseline (abidiff) ------------------------
# tests/abi/abi_check.sh says what fails. Regenerate the baseline after an intended
# change from a Release build: cmake --build build --target abi-baseline
set(SW_ABI_BASELINE ${SW_ABI_DIR}/libsinew.abi)
add_test(NAME abi_abidiff
  COMMAND sh ${SW_ABI_DIR}/abi_check.sh ${SW_ABI_BASELINE} $<TARGET_FILE:sinew> ${SW_ABI_HEADERS})
set_tests_properties(abi_abidiff PROPERTIES LABELS abi TIMEOUT 60 SKIP_RETURN_CODE 77)
add_custom_target(abi-baseline
  COMMAND sh ${SW_ABI_DIR}/abi_check.sh --write ${SW_ABI_BASELINE} $<TARGET_FILE:sinew>
          ${SW_ABI_HEADERS}
  DEPENDS sinew
  COMMENT "Writing the ABI baseline tests/abi/libsinew.abi" VERBATIM)
