/* A minimal PNG writer for sinew-render's images: 8-bit RGB, no interlace, every
 * scanline with filter 0, and a zlib stream of *stored* (uncompressed) deflate blocks,
 * so no compression library is needed. CRC-32 (PNG chunks) and Adler-32 (zlib trailer)
 * are computed here. Files are about as large as the raw pixels; that is the price of
 * having no zlib dependency. */
#ifndef SW_PNG_WRITE_H
#define SW_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>

#include "sw_error.h"

/* Largest width or height accepted (keeps the zlib stream well below 2^31 bytes). */
#define SW_PNG_MAX_DIM 16384

/* Writes the w x h image `rgb` (row-major, top row first, 3 bytes a pixel) to `path`.
 * The file appears atomically: it is written to "<path>.tmp" and renamed, and the
 * temporary is removed on failure. Errors: INVALID_ARGUMENT (NULL, size outside
 * 1..SW_PNG_MAX_DIM), OUT_OF_MEMORY, IO (message names the path). */
sinew_result sw_write_png(const char *path, int w, int h, const uint8_t *rgb, sw_error *err);

/* CRC-32 (ISO 3309 / PNG, reflected polynomial 0xEDB88320) of `n` bytes continuing
 * from `crc` (start with 0). */
uint32_t sw_crc32(uint32_t crc, const uint8_t *p, size_t n);

/* Adler-32 (RFC 1950) of `n` bytes continuing from `adler` (start with 1). */
uint32_t sw_adler32(uint32_t adler, const uint8_t *p, size_t n);

#endif
