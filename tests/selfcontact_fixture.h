/* The self-contact tests' shared random numbers (test_selfcontact.c,
 * test_selfcontact_kernels.c): splitmix64 from a file-wide state a test may reseed. */
#ifndef SW_SELFCONTACT_FIXTURE_H
#define SW_SELFCONTACT_FIXTURE_H

#include <stdint.h>

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static inline double urand(void) { /* splitmix64 -> [0, 1) */
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}
static inline double srand1(void) {
    return 2 * urand() - 1;
}

#endif
