/* Version queries and result strings of the public ABI. */
#include "sinew/sinew.h"

#define SW_STR2(x) #x
#define SW_STR(x) SW_STR2(x)

SINEW_API uint32_t sinew_version(void) {
    return SINEW_VERSION;
}

SINEW_API const char *sinew_version_string(void) {
    return SW_STR(SINEW_VERSION_MAJOR) "." SW_STR(SINEW_VERSION_MINOR) "." SW_STR(
        SINEW_VERSION_PATCH);
}

SINEW_API int sinew_version_compatible(uint32_t header_version) {
    uint32_t major = header_version >> 16, minor = (header_version >> 8) & 0xffu;
    return major == SINEW_VERSION_MAJOR && minor <= SINEW_VERSION_MINOR;
}

SINEW_API const char *sinew_result_string(sinew_result result) {
    switch (result) {
    case SINEW_OK:
        return "ok";
    case SINEW_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case SINEW_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case SINEW_ERROR_IO:
        return "input/output error";
    case SINEW_ERROR_PARSE:
        return "malformed input";
    case SINEW_ERROR_DEGENERATE:
        return "degenerate geometry";
    case SINEW_ERROR_NOT_FINITE:
        return "not a finite number";
    case SINEW_ERROR_CORRUPT:
        return "corrupt data";
    case SINEW_ERROR_VERSION:
        return "unsupported version";
    case SINEW_ERROR_CAPACITY:
        return "reserved capacity exceeded";
    case SINEW_ERROR_NOT_CONVERGED:
        return "solver did not converge";
    case SINEW_ERROR_UNSUPPORTED:
        return "unsupported feature";
    case SINEW_RESULT_COUNT_:
        break;
    }
    return "unknown result code";
}
