/* The byte layout of every public struct and enum, as one X-macro list, so that a C
 * translation unit and a C++ one can each evaluate it and compare: a host written in
 * C++ must see exactly the structs the C library was compiled with. */
#ifndef SW_ABI_LAYOUT_H
#define SW_ABI_LAYOUT_H

#include <stddef.h>

#include <sinew/sinew.h>

#define SW_ABI_LAYOUT(X)                                                                           \
    X(sizeof(sinew_result))                                                                        \
    X(sizeof(sinew_log_level))                                                                     \
    X(sizeof(sinew_step_mode))                                                                     \
    X(sizeof(sinew_allocator))                                                                     \
    X(offsetof(sinew_allocator, alloc))                                                            \
    X(offsetof(sinew_allocator, free))                                                             \
    X(offsetof(sinew_allocator, user))                                                             \
    X(sizeof(sinew_logger))                                                                        \
    X(offsetof(sinew_logger, log))                                                                 \
    X(offsetof(sinew_logger, user))                                                                \
    X(offsetof(sinew_logger, max_level))                                                           \
    X(sizeof(sinew_blob_def))                                                                      \
    X(offsetof(sinew_blob_def, struct_size))                                                       \
    X(offsetof(sinew_blob_def, path))                                                              \
    X(offsetof(sinew_blob_def, data))                                                              \
    X(offsetof(sinew_blob_def, data_size))                                                         \
    X(offsetof(sinew_blob_def, allocator))                                                         \
    X(offsetof(sinew_blob_def, logger))                                                            \
    X(sizeof(sinew_instance_def))                                                                  \
    X(offsetof(sinew_instance_def, struct_size))                                                   \
    X(offsetof(sinew_instance_def, mode))                                                          \
    X(offsetof(sinew_instance_def, max_newton_iters))                                              \
    X(offsetof(sinew_instance_def, allocator))                                                     \
    X(offsetof(sinew_instance_def, logger))                                                        \
    X(offsetof(sinew_instance_def, max_contact_pairs))                                             \
    X(offsetof(sinew_instance_def, tasks))                                                         \
    X(offsetof(sinew_instance_def, self_contact))                                                  \
    X(offsetof(sinew_instance_def, profiler))                                                      \
    X(sizeof(sinew_profiler))                                                                      \
    X(sizeof(sinew_self_contact))                                                                  \
    X(sizeof(sinew_task_callbacks))                                                                \
    X(offsetof(sinew_task_callbacks, enqueue))                                                     \
    X(offsetof(sinew_task_callbacks, finish))                                                      \
    X(offsetof(sinew_task_callbacks, worker_count))                                                \
    X(offsetof(sinew_task_callbacks, user))                                                        \
    X(sizeof(sinew_step_stats))                                                                    \
    X(offsetof(sinew_step_stats, residual))                                                        \
    X(offsetof(sinew_step_stats, energy))                                                          \
    X(offsetof(sinew_step_stats, ms_skin))                                                         \
    X(offsetof(sinew_step_stats, ms_output))                                                       \
    X(offsetof(sinew_step_stats, active_vertices))                                                 \
    X(offsetof(sinew_step_stats, budget_exceeded))                                                 \
    X(offsetof(sinew_step_stats, ms_self_contact))                                                 \
    X(offsetof(sinew_step_stats, beyond_training_deg))                                             \
    X(sizeof(sinew_blob_provenance))                                                               \
    X(offsetof(sinew_blob_provenance, source_hash))                                                \
    X(offsetof(sinew_blob_provenance, options_hash))

#ifdef __cplusplus
extern "C" {
#endif

/* Number of entries in SW_ABI_LAYOUT. */
size_t sw_abi_layout_count_c(void);

/* Entry i of SW_ABI_LAYOUT as evaluated by the C compiler (C99). */
size_t sw_abi_layout_value_c(size_t i);

#ifdef __cplusplus
}
#endif
#endif
