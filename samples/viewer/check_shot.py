#!/usr/bin/env python3
"""Checks sinew-view screenshots: the character is on screen (pixels unlike the
background in the picture's centre) and two views differ (the silhouettes of plain
skinning and sinew where the correction is).

  check_shot.py present A.png            the character fills part of the centre
  check_shot.py differ A.png B.png MIN   at least MIN pixels where one shows the character
                                         and the other the background
"""
import struct
import sys
import zlib

BACKGROUND = (31, 33, 38)  # the viewer's clear colour, 0.12 0.13 0.15


def read_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        sys.exit(f'{path}: not a PNG')
    pos, idat, w = 8, b'', 0
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, colour = struct.unpack('>IIBB', body[:10])
            if depth != 8 or colour != 2:
                sys.exit(f'{path}: not 8-bit RGB')
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    raw, row, out, prev = zlib.decompress(idat), 3 * w, [], bytearray(3 * w)
    for y in range(h):
        f, line = raw[y * (row + 1)], bytearray(raw[y * (row + 1) + 1:(y + 1) * (row + 1)])
        for i in range(row):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out.append(bytes(line))
        prev = line
    return w, h, out


def mask(w, h, rows, top=0):
    """1 where a pixel is not the background (below the HUD's rows)."""
    m = []
    for y in range(h):
        r = rows[y]
        m.append([y >= top and max(abs(r[3 * x + k] - BACKGROUND[k]) for k in range(3)) > 12
                  for x in range(w)])
    return m


def main():
    if sys.argv[1] == 'present':
        w, h, rows = read_png(sys.argv[2])
        m = mask(w, h, rows)
        y0, y1, x0, x1 = h // 4, 3 * h // 4, w // 4, 3 * w // 4
        n = sum(m[y][x] for y in range(y0, y1) for x in range(x0, x1))
        share = n / ((y1 - y0) * (x1 - x0))
        print(f'{sys.argv[2]}: {share:.3f} of the centre shows the character')
        sys.exit(0 if share > 0.02 else 1)
    if sys.argv[1] == 'differ':
        wa, ha, a = read_png(sys.argv[2])
        wb, hb, b = read_png(sys.argv[3])
        if (wa, ha) != (wb, hb):
            sys.exit('the pictures differ in size')
        top = ha // 8  # the HUD's lines differ anyway
        ma, mb = mask(wa, ha, a, top), mask(wb, hb, b, top)
        n = sum(ma[y][x] != mb[y][x] for y in range(ha) for x in range(wa))
        print(f'{n} pixels differ between the silhouettes (at least {sys.argv[4]} wanted)')
        sys.exit(0 if n >= int(sys.argv[4]) else 1)
    sys.exit('usage: check_shot.py present A.png | differ A.png B.png MIN')


main()
