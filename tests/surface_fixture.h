/* Closed and open test surfaces for the meshers' tests (test_tet_lattice.c,
 * test_tetgen_run.c): axis-aligned boxes and a UV sphere, outward triangles. */
#ifndef SW_SURFACE_FIXTURE_H
#define SW_SURFACE_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "sw_mesh.h"

#define SW_PI 3.14159265358979323846

/* An axis-aligned box [lo, lo + size] as 12 outward triangles, appended to m at vertex
 * offset m->nverts (m has room); `skip` leaves out the two triangles of face `skip`
 * (0..5: -x +x -y +y -z +z) or none (-1). */
static inline void add_box(sw_trimesh *m, const double lo[3], double size, int skip) {
    static const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    int32_t base = m->nverts;
    for (int q = 0; q < 8; ++q)
        for (int a = 0; a < 3; ++a)
            m->X[3 * (base + q) + a] = lo[a] + size * ((q >> a) & 1);
    m->nverts += 8;
    for (int f = 0; f < 6; ++f) {
        if (f == skip) continue;
        const int *c = faces[f];
        int32_t *t = m->tris + 3 * m->ntris;
        t[0] = base + c[0], t[1] = base + c[1], t[2] = base + c[2];
        t[3] = base + c[0], t[4] = base + c[2], t[5] = base + c[3];
        m->ntris += 2;
    }
}

static inline sw_trimesh boxes(int n, double (*lo)[3], double size, int skip) {
    sw_trimesh m = {0};
    m.X = malloc(sizeof(double) * 24 * n);
    m.tris = malloc(sizeof(int32_t) * 36 * n);
    for (int i = 0; i < n; ++i)
        add_box(&m, lo[i], size, skip);
    return m;
}

/* A UV sphere of radius r: nlat x nlon quads split into outward triangles. */
static inline sw_trimesh sphere(double r, int nlat, int nlon) {
    sw_trimesh m = {0};
    m.nverts = 2 + (nlat - 1) * nlon;
    m.X = malloc(sizeof(double) * 3 * m.nverts);
    m.tris = malloc(sizeof(int32_t) * 6 * nlat * nlon);
    double *x = m.X;
    x[0] = 0, x[1] = 0, x[2] = r;
    for (int i = 1; i < nlat; ++i)
        for (int j = 0; j < nlon; ++j) {
            double th = SW_PI * i / nlat, ph = 2 * SW_PI * j / nlon;
            double *p = x + 3 * (1 + (i - 1) * nlon + j);
            p[0] = r * sin(th) * cos(ph), p[1] = r * sin(th) * sin(ph), p[2] = r * cos(th);
        }
    int32_t s = m.nverts - 1;
    x[3 * s] = 0, x[3 * s + 1] = 0, x[3 * s + 2] = -r;
    int32_t *t = m.tris;
    for (int j = 0; j < nlon; ++j) {
        int32_t a = 1 + j, b = 1 + (j + 1) % nlon;
        *t++ = 0, *t++ = a, *t++ = b;
        int32_t c = 1 + (nlat - 2) * nlon + j, d = 1 + (nlat - 2) * nlon + (j + 1) % nlon;
        *t++ = s, *t++ = d, *t++ = c;
    }
    for (int i = 1; i + 1 < nlat; ++i)
        for (int j = 0; j < nlon; ++j) {
            int32_t a = 1 + (i - 1) * nlon + j, b = 1 + (i - 1) * nlon + (j + 1) % nlon;
            int32_t c = a + nlon, d = b + nlon;
            *t++ = a, *t++ = c, *t++ = d;
            *t++ = a, *t++ = d, *t++ = b;
        }
    m.ntris = (int32_t)((t - m.tris) / 3);
    return m;
}

#endif
