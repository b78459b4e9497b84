/* A compressed PNG for screenshots (zlib's deflate), small enough to commit. */
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "viewer.h"

static void be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24), p[1] = (uint8_t)(v >> 16), p[2] = (uint8_t)(v >> 8),
    p[3] = (uint8_t)v;
}

static int chunk(FILE *f, const char *type, const uint8_t *data, uint32_t n) {
    uint8_t h[8];
    be32(h, n);
    memcpy(h + 4, type, 4);
    uLong crc = crc32(0, h + 4, 4);
    if (n) crc = crc32(crc, data, n);
    uint8_t c[4];
    be32(c, (uint32_t)crc);
    return fwrite(h, 1, 8, f) == 8 && (!n || fwrite(data, 1, n, f) == n) && fwrite(c, 1, 4, f) == 4;
}

int vw_write_png(const char *path, int w, int h, const uint8_t *rgb) {
    size_t row = 3 * (size_t)w + 1, raw_n = row * (size_t)h;
    uint8_t *raw = malloc(raw_n);
    uLongf zn = compressBound((uLong)raw_n);
    uint8_t *z = malloc(zn);
    FILE *f = NULL;
    int ok = raw && z;
    for (int y = 0; ok && y < h; ++y) { /* filter "up" (2): smooth pictures deflate better */
        uint8_t *o = raw + row * (size_t)y;
        const uint8_t *cur = rgb + 3 * (size_t)w * y, *up = y ? cur - 3 * (size_t)w : NULL;
        o[0] = 2;
        for (size_t i = 0; i < 3 * (size_t)w; ++i)
            o[1 + i] = (uint8_t)(cur[i] - (up ? up[i] : 0));
    }
    ok = ok && compress2(z, &zn, raw, (uLong)raw_n, 9) == Z_OK;
    if (ok) ok = (f = fopen(path, "wb")) != NULL;
    uint8_t ihdr[13] = {0};
    be32(ihdr, (uint32_t)w), be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8, ihdr[9] = 2; /* 8-bit RGB */
    ok = ok && fwrite("\x89PNG\r\n\x1a\n", 1, 8, f) == 8 && chunk(f, "IHDR", ihdr, 13) &&
         chunk(f, "IDAT", z, (uint32_t)zn) && chunk(f, "IEND", NULL, 0);
    if (f && fclose(f) != 0) ok = 0;
    free(raw), free(z);
    return ok;
}
