/* Two characters as one (the two-body reference of character contact): the simulator solves
 * both in one system, and its self-contact, which detects any surface vertex inside any
 * tet not its own neighbour, is then the contact between them with the same penalty law
 * (thesis eqs. 3.4-3.6). The second body is a copy of the first moved by a rest offset
 * far enough that no point of one lies near the other at rest (the detector projects a
 * penetrating point onto the closest rest surface, which must be its own body's). */
#ifndef SW_CHARACTER_PAIR_H
#define SW_CHARACTER_PAIR_H

#include "sw_error.h"
#include "sw_mesh.h"

/* *out = a and a copy of a at rest X + offset: vertices, tets, bones (parents) and
 * weights of the copy follow a's, numbered after a's; material and painting shared; no
 * clip, render mesh or names. */
sinew_result sw_character_pair(const sw_character *a, const double offset[3], sw_character *out,
                               sw_error *err);

/* The pair's bone transforms (2 nbones, 12 each: R row-major, t) with the first body at
 * Ta and the second at Tb (nbones each, rest -> world of the single character): the
 * second's rest is moved by `offset`, so its transforms are Tb composed with -offset. */
void sw_character_pair_transforms(int32_t nbones, const double *Ta, const double *Tb,
                                  const double offset[3], double *T);

#endif
