/* Monotonic wall-clock time, for the bake's stage timings and the step's phase times. */
#ifndef SW_CLOCK_H
#define SW_CLOCK_H

/* Monotonic wall-clock seconds (CLOCK_MONOTONIC: no lock, no allocation). */
double sw_now_seconds(void);

#endif
