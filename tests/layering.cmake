# Layering (DESIGN.md §2): every subsystem library sees only its own headers and those of
# the folders below it, so an include that runs the wrong way fails to build. Each test
# compiles a one-line probe with exactly the include path of a subsystem's library:
# a header from below must be found, one from above must not be.
#   sinew_layering_test(NAME TARGET HEADER visible|hidden)
function(sinew_layering_test name target header visibility)
  set(probe ${CMAKE_CURRENT_BINARY_DIR}/layering_${name}.c)
  file(WRITE ${probe} "#include \"${header}\"\nint sw_layering_probe;\n")
  add_test(NAME layering_${name}
    COMMAND ${CMAKE_C_COMPILER} -std=c17 -D_POSIX_C_SOURCE=200809L -fsyntax-only
            "-I$<JOIN:$<TARGET_PROPERTY:${target},INCLUDE_DIRECTORIES>,;-I>" ${probe}
    COMMAND_EXPAND_LISTS)
  if(visibility STREQUAL "hidden")
    set_tests_properties(layering_${name} PROPERTIES
      PASS_REGULAR_EXPRESSION "${header}: No such file or directory")
  endif()
  set_tests_properties(layering_${name} PROPERTIES LABELS layering)
endfunction()

sinew_layering_test(math_sees_core sinew_math thread_pool.h visible)
sinew_layering_test(math_cannot_see_blob sinew_math blob_view.h hidden)
sinew_layering_test(fem_cannot_see_contact sinew_fem pose_space.h hidden)
sinew_layering_test(contact_sees_fem sinew_contact reduced_map.h visible)
sinew_layering_test(solver_cannot_see_instance sinew_solver instance_internal.h hidden)
sinew_layering_test(runtime_cannot_see_precompute sinew_instance fullsim.h hidden)
sinew_layering_test(io_cannot_see_reference sinew_pc_io fullsim.h hidden)
sinew_layering_test(reference_cannot_see_bake sinew_pc_reference bake.h hidden)
sinew_layering_test(bake_sees_reference sinew_pc_bake fullsim.h visible)

# No stage of the bake includes its orchestrator (tests/bake_includes.cmake).
add_test(NAME layering_bake_includes
  COMMAND ${CMAKE_COMMAND} -DDIR=${CMAKE_CURRENT_LIST_DIR}/../precompute/bake
          -P ${CMAKE_CURRENT_LIST_DIR}/bake_includes.cmake)
set_tests_properties(layering_bake_includes PROPERTIES LABELS layering)
