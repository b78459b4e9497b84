/* Version and result-string queries of the public ABI. */
#include "sinew/sinew.h"
#include "sw_test.h"

TEST(version_matches_header) {
    ENSURE(sinew_version() == SINEW_VERSION);
    ENSURE(sinew_version_compatible(SINEW_VERSION));
    ENSURE(!sinew_version_compatible(SINEW_VERSION + (1u << 16)));
    ENSURE(!sinew_version_compatible(SINEW_VERSION + (1u << 8)));
    char buf[32];
    snprintf(buf, sizeof buf, "%d.%d.%d", SINEW_VERSION_MAJOR, SINEW_VERSION_MINOR,
             SINEW_VERSION_PATCH);
    ENSURE(strcmp(buf, sinew_version_string()) == 0);
}

TEST(every_result_has_a_distinct_string) {
    for (int r = 0; r < SINEW_RESULT_COUNT_; ++r) {
        const char *s = sinew_result_string((sinew_result)r);
        ENSURE(s && *s && strcmp(s, "unknown result code") != 0);
        for (int q = 0; q < r; ++q)
            ENSURE(strcmp(s, sinew_result_string((sinew_result)q)) != 0);
    }
    ENSURE(strcmp(sinew_result_string((sinew_result)9999), "unknown result code") == 0);
}

TEST(def_defaults_carry_their_size) {
    sinew_blob_def b = sinew_blob_def_default();
    sinew_instance_def i = sinew_instance_def_default();
    ENSURE(b.struct_size == sizeof b && b.path == NULL && b.allocator.alloc == NULL);
    ENSURE(i.struct_size == sizeof i && i.mode == SINEW_STEP_QUASISTATIC);
}

SW_TEST_MAIN(CASE(version_matches_header), CASE(every_result_has_a_distinct_string),
             CASE(def_defaults_carry_their_size))
