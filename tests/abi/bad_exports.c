/* A deliberately broken stand-in for libsinew, built only so that abi_exports_rejects
 * can prove the export checker fails loudly. Each definition is one kind of violation. */
#include <sinew/sinew_base.h>

/* Correct: declared in the header and prefixed. */
SINEW_API uint32_t sinew_version(void) {
    return SINEW_VERSION;
}

/* Violation: an internal helper made visible without the sinew_ prefix. */
SINEW_API int sw_leaked_helper(void) {
    return 1;
}

/* Violation: prefixed, but no public header declares it. */
SINEW_API int sinew_undeclared_helper(void) {
    return 2;
}

/* Violation: a writable global exported to every host. */
SINEW_API int sinew_shared_counter = 3;

/* sinew_version_string, sinew_version_compatible and sinew_result_string are declared
 * but deliberately missing: the checker must report them too. */
