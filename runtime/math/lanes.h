/* Two doubles side by side: SSE2's width, which every x86-64 has, and a pair of lanes
 * elsewhere (GCC and clang vector extensions). Loads and stores through it need only a
 * double's alignment. A kernel that keeps each lane's operations in the order of its
 * one-value loop gives bitwise that loop's result (the build contracts no multiply-add:
 * -ffp-contract=off), so vectorising it this way changes no figure. */
#ifndef SW_LANES_H
#define SW_LANES_H

typedef double sw_v2d __attribute__((vector_size(16), aligned(8)));

#endif
