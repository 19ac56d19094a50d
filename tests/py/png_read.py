# SPDX-License-Identifier: Apache-2.0
"""A small PNG reader that shares no code with vdbpack's writer (zlib +
struct, chunk CRCs checked, filters undone), for the tests.
read(path) -> (w, h, rows) with rows[y] a bytearray of RGBA.
As a script: png_read.py FILE [columns] prints "W H", then the RGBA at each
"x y" query on stdin, or with `columns` the covered (alpha > 0) pixels per
column."""
import struct, sys, zlib


def read(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG signature'
    pos, idat, ihdr = 8, b'', None
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        crc, = struct.unpack('>I', data[pos + 8 + n:pos + 12 + n])
        assert zlib.crc32(kind + body) & 0xffffffff == crc, 'bad CRC in ' + kind.decode()
        if kind == b'IHDR': ihdr = struct.unpack('>IIBBBBB', body)
        if kind == b'IDAT': idat += body
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = ihdr
    assert depth == 8 and ctype == 6 and interlace == 0, 'expected 8-bit RGBA, not interlaced'
    raw = zlib.decompress(idat)
    stride, bpp = 4 * w, 4
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, rows


if __name__ == '__main__':
    w, h, rows = read(sys.argv[1])
    print(w, h)
    mode = sys.argv[2] if len(sys.argv) > 2 else 'points'
    if mode == 'columns':
        # "covered" for every column: how many pixels in it have alpha > 0
        print(' '.join(str(sum(1 for y in range(h) if rows[y][4 * x + 3])) for x in range(w)))
    else:
        for q in sys.stdin:
            x, y = map(int, q.split())
            print(*rows[y][4 * x:4 * x + 4])
