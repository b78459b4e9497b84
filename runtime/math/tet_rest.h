/* A tet's rest data, Dm^-1 and volume: the elastic kernels' (fem_corot.h), the bake's and
 * the blob's, which derives a condensation tet's from its rest corners when the blob does
 * not store it (blob_view.h, sw_blob_tet_dminv). One function, so all of them agree bit
 * for bit. Private to the runtime. */
#ifndef SW_TET_REST_H
#define SW_TET_REST_H

/* Rest-state data of one tet, X its 4 corners (12 doubles): Dm^-1 (9, row-major) and rest
 * volume. Returns 0 and leaves outputs untouched when the rest tet is degenerate (|det Dm|
 * below 1e-300 or non-finite); 1 on success. Negative rest volume is allowed (vol is then
 * |vol| and Dm^-1 still maps to F = I at rest). */
int sw_tet_rest(const double X[12], double DmInv[9], double *vol);

#endif
