/* Everything the command-line tools share, by concept: flag values (tool_args.h), files
 * (tool_files.h), a run's messages, times and progress (tool_run.h), and with
 * SW_TOOL_CHARACTER_ARGS or SW_TOOL_REFERENCE_ARGS defined before it the character inputs
 * (character_args.h) and the reference's solver options (reference_args.h). */
#ifndef SW_TOOL_COMMON_H
#define SW_TOOL_COMMON_H

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sinew/sinew.h"
#include "sw_error.h"
#include "tool_args.h"
#include "tool_files.h"
#include "tool_flags.h"
#include "tool_run.h"

#ifndef SINEW_SHARED_DATA_DIR
#define SINEW_SHARED_DATA_DIR "../shared/data"
#endif
#endif

#ifdef SW_TOOL_CHARACTER_ARGS
#include "character_args.h"
#include "mesh_io.h"
#include "samples.h"
#endif

#ifdef SW_TOOL_REFERENCE_ARGS
#include "reference_args.h"
#endif
