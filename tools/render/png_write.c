/* PNG = signature + IHDR + IDAT* + IEND (PNG spec §5); the IDAT payload is a zlib
 * stream (RFC 1950) whose deflate data (RFC 1951 §3.2.4) is a run of stored blocks of
 * at most 65535 bytes each. */
#include "png_write.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest payload of one stored deflate block (LEN is 16 bits). */
#define STORED_MAX 65535u
/* IDAT chunks are cut at this size; any size is legal, smaller chunks only let a
 * reader stream. */
#define IDAT_MAX ((size_t)1 << 20)

uint32_t sw_crc32(uint32_t crc, const uint8_t *p, size_t n) {
    /* Byte-wise table built per call: 256 steps, negligible next to an image, and no
     * global state to initialise across threads. */
    uint32_t table[256];
    for (uint32_t i = 0; i < 256; ++i) {
        uint32_t c = i;
        for (int k = 0; k < 8; ++k)
            c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        table[i] = c;
    }
    crc = ~crc;
    for (size_t i = 0; i < n; ++i)
        crc = table[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}

uint32_t sw_adler32(uint32_t adler, const uint8_t *p, size_t n) {
    uint32_t a = adler & 0xFFFFu, b = adler >> 16;
    while (n) {
        /* 5552 is the largest run for which b cannot overflow 32 bits (RFC 1950 §9). */
        size_t run = n < 5552 ? n : 5552;
        n -= run;
        while (run--) {
            a += *p++;
            b += a;
        }
        a %= 65521u;
        b %= 65521u;
    }
    return (b << 16) | a;
}

static void put_be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* One chunk: length, type, data, CRC over type + data. Returns 0 on a write error. */
static int write_chunk(FILE *f, const char type[4], const uint8_t *data, size_t n) {
    uint8_t head[8], tail[4];
    put_be32(head, (uint32_t)n);
    memcpy(head + 4, type, 4);
    uint32_t crc = sw_crc32(0, head + 4, 4);
    crc = sw_crc32(crc, data, n);
    put_be32(tail, crc);
    return fwrite(head, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) &&
           fwrite(tail, 1, 4, f) == 4;
}

/* The zlib stream of the filtered scanlines (filter byte 0 + the row). */
static uint8_t *zlib_stored(int w, int h, const uint8_t *rgb, size_t *out_len) {
    size_t row = 1 + 3 * (size_t)w;
    size_t raw = row * (size_t)h;
    size_t nblocks = (raw + STORED_MAX - 1) / STORED_MAX;
    size_t len = 2 + raw + 5 * nblocks + 4;
    uint8_t *z = malloc(len);
    if (!z) return NULL;
    uint8_t *o = z;
    /* CMF 0x78: deflate, 32K window; FLG 0x01 makes (CMF*256 + FLG) % 31 == 0, level 0. */
    *o++ = 0x78;
    *o++ = 0x01;
    uint32_t adler = 1;
    size_t left = raw, in_row = 0; /* in_row: bytes of the current scanline emitted */
    int y = 0;
    while (left) {
        uint32_t n = (uint32_t)(left < STORED_MAX ? left : STORED_MAX);
        left -= n;
        /* BFINAL on the last block, BTYPE 00; the rest of the byte is padding. */
        *o++ = left ? 0x00 : 0x01;
        *o++ = (uint8_t)n;
        *o++ = (uint8_t)(n >> 8);
        *o++ = (uint8_t)~n;
        *o++ = (uint8_t)(~n >> 8);
        uint8_t *start = o;
        while (n) {
            if (in_row == 0) {
                *o++ = 0; /* filter type None */
                in_row = 1;
                n--;
                continue;
            }
            size_t take = row - in_row;
            if (take > n) take = n;
            memcpy(o, rgb + (size_t)y * 3 * (size_t)w + (in_row - 1), take);
            o += take;
            n -= (uint32_t)take;
            in_row += take;
            if (in_row == row) {
                in_row = 0;
                y++;
            }
        }
        adler = sw_adler32(adler, start, (size_t)(o - start));
    }
    put_be32(o, adler);
    o += 4;
    *out_len = (size_t)(o - z);
    return z;
}

static int write_png_file(FILE *f, int w, int h, const uint8_t *z, size_t zlen) {
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    uint8_t ihdr[13];
    put_be32(ihdr, (uint32_t)w);
    put_be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8;  /* bit depth */
    ihdr[9] = 2;  /* colour type: truecolour RGB */
    ihdr[10] = 0; /* compression: deflate */
    ihdr[11] = 0; /* filter method 0 */
    ihdr[12] = 0; /* no interlace */
    if (fwrite(sig, 1, 8, f) != 8 || !write_chunk(f, "IHDR", ihdr, sizeof ihdr)) return 0;
    for (size_t off = 0; off < zlen; off += IDAT_MAX) {
        size_t n = zlen - off < IDAT_MAX ? zlen - off : IDAT_MAX;
        if (!write_chunk(f, "IDAT", z + off, n)) return 0;
    }
    return write_chunk(f, "IEND", NULL, 0);
}

sinew_result sw_write_png(const char *path, int w, int h, const uint8_t *rgb, sw_error *err) {
    if (!path || !rgb)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT, "sw_write_png: NULL %s",
                            path ? "pixels" : "path");
    if (w < 1 || h < 1 || w > SW_PNG_MAX_DIM || h > SW_PNG_MAX_DIM)
        return sw_error_set(err, SINEW_ERROR_INVALID_ARGUMENT,
                            "%s: image size %d x %d outside 1..%d", path, w, h, SW_PNG_MAX_DIM);
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 5);
    if (!tmp) return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp", 5);
    size_t zlen = 0;
    uint8_t *z = zlib_stored(w, h, rgb, &zlen);
    if (!z) {
        free(tmp);
        return sw_error_set(err, SINEW_ERROR_OUT_OF_MEMORY, "%s: out of memory for %d x %d", path,
                            w, h);
    }
    sinew_result rc = SINEW_OK;
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        rc = sw_error_set(err, SINEW_ERROR_IO, "%s: cannot open for writing (%s)", tmp,
                          strerror(errno));
    } else {
        int ok = write_png_file(f, w, h, z, zlen);
        ok = (fflush(f) == 0) && ok;
        ok = (fclose(f) == 0) && ok;
        if (!ok) {
            rc = sw_error_set(err, SINEW_ERROR_IO, "%s: write failed (%s)", tmp, strerror(errno));
        } else if (rename(tmp, path) != 0) {
            rc = sw_error_set(err, SINEW_ERROR_IO, "%s: cannot rename to %s (%s)", tmp, path,
                              strerror(errno));
        }
        if (rc) remove(tmp);
    }
    free(z);
    free(tmp);
    return rc;
}
