/* Labels drawn into an RGB image with a 5 x 7 pixel bitmap font: digits, capital letters
 * (lower case is drawn as capitals) and a few signs, enough for a picture to name its
 * columns and number its frames without a font library. */
#ifndef SW_TEXT5X7_H
#define SW_TEXT5X7_H

#include <stdint.h>

/* Width in pixels of s drawn at `scale` (each font pixel a scale x scale block): 6 font
 * pixels a character (5 and a gap), less the last gap. */
int sw_text_width(const char *s, int scale);

/* Draws s into rgb (w x h, 3 bytes a pixel, top row first) with its top-left corner at
 * (x, y), each font pixel a scale x scale block of colour; pixels outside the image are
 * skipped, characters the font lacks are drawn as blanks. */
void sw_draw_text(uint8_t *rgb, int w, int h, int x, int y, int scale, const char *s,
                  const uint8_t colour[3]);

#endif
