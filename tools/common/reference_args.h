/* The full-space reference's solver options, shared by sinew-fullsim, sinew-bench and
 * sinew-bake. */
#ifndef SW_REFERENCE_ARGS_H
#define SW_REFERENCE_ARGS_H

#include "fullsim.h"
#include "tool_flags.h"

#define SW_REFERENCE_NFLAGS 4

/* The reference's solver flags, bound to p, into f[0..SW_REFERENCE_NFLAGS); returns their
 * count. */
size_t sw_reference_flags(sw_fullsim_params *p, sw_flag *f);

#endif
