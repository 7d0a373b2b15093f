#!/usr/bin/env bash
# The figures' formats and resolution (--figure-format, --figure-dpi), read by
# other programs: poppler's pdfinfo and pdftoppm read the PDF, Python's XML
# parser the SVG, and the PDF's pixels as poppler draws them are compared with
# the PNG's. Needs DYNSUB, DATA and an X display.
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
require_colin27

"$DYNSUB" segment "$templates/ch2.nii.gz" --landmarks "$DATA/Landmarks/caudate_left.mrk.json" --no-figures \
  --out "$work/caudate" >/dev/null 2>&1
check "segment succeeds" test -s "$work/caudate/surface.vtp"
render() {  # render FORMAT DPI: the three figures into $work/FORMAT-DPI
  "$DYNSUB" render --surface "$work/caudate/surface.vtp" --image "$templates/ch2.nii.gz" \
    --landmarks "$DATA/Landmarks/caudate_left.mrk.json" --convergence "$work/caudate/convergence.csv" \
    --figure-format "$1" --figure-dpi "$2" --out "$work/$1-$2" >/dev/null
  check "render --figure-format $1 --figure-dpi $2 succeeds" test $? -eq 0
}
for format in png pdf svg; do
  render "$format" 150
  for name in slices surface3d convergence; do
    check "render --figure-format $format writes $name.$format" test -s "$work/$format-150/$name.$format"
  done
done

# PNG: 1.5 times the pixels of the default (1200 x 800, 800 x 800, 900 x 500),
# and the resolution recorded for printing (150 dpi = 5906 pixels per metre).
png_size() {  # png_size FILE WIDTH HEIGHT
  python3 - "$@" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
size = struct.unpack('>II', data[16:24])
at = data.find(b'pHYs')
physical = struct.unpack('>IIB', data[at + 4:at + 13]) if at > 0 else None
ok = size == (int(sys.argv[2]), int(sys.argv[3])) and physical == (5906, 5906, 1)
print(sys.argv[1], size, physical)
sys.exit(0 if ok else 1)
PY
}
check "slices.png at 150 dpi: 1800 x 1200 pixels, pHYs 150 dpi" png_size "$work/png-150/slices.png" 1800 1200
check "surface3d.png at 150 dpi: 1200 x 1200 pixels" png_size "$work/png-150/surface3d.png" 1200 1200
check "convergence.png at 150 dpi: 1350 x 750 pixels" png_size "$work/png-150/convergence.png" 1350 750

# PDF and SVG: the page is the figure's nominal size at any dpi (12 x 8 in is
# 864 x 576 points), whatever the raster's resolution.
page_size() { pdfinfo "$1" | sed -n 's/^Page size: *\([0-9.]* x [0-9.]*\) pts.*/\1/p'; }
check "slices.pdf is 864 x 576 pt" test "$(page_size "$work/pdf-150/slices.pdf")" = "864 x 576"
check "surface3d.pdf is 576 x 576 pt" test "$(page_size "$work/pdf-150/surface3d.pdf")" = "576 x 576"
check "convergence.pdf is 648 x 360 pt" test "$(page_size "$work/pdf-150/convergence.pdf")" = "648 x 360"
# Below 72 dpi GL2PS's page is smaller than the nominal one; it is enlarged
# to fill it (pdftocairo -expand): drawn by poppler at 50 dpi, slices.pdf at
# 50 dpi has no white border (the figure's own edges are black).
render pdf 50
pdftoppm -r 50 -singlefile "$work/pdf-50/slices.pdf" "$work/slices-50"
check "slices.pdf at 50 dpi fills its 864 x 576 pt page" /usr/bin/python3 - "$work/slices-50.ppm" <<'PY'
import re, sys
import numpy as np
data = open(sys.argv[1], 'rb').read()
header = re.match(rb'P6\s+(\d+)\s+(\d+)\s+\d+\s', data)  # one whitespace byte after the maximum value
width, height = int(header[1]), int(header[2])
image = np.frombuffer(data, np.uint8, width * height * 3, header.end()).reshape(height, width, 3)
corners = [image[0, 0], image[0, -1], image[-1, 0], image[-1, -1]]
print((width, height), [tuple(c) for c in corners])
sys.exit(0 if (width, height) == (600, 400) and all(c.max() < 128 for c in corners) else 1)
PY

# The PDF drawn by poppler at 150 dpi against the PNG at 150 dpi: the same
# picture. Compared in blocks of 6 x 6 pixels (1/25 in), as the eye sees a
# print: text drawn from outlines and by FreeType differs in its anti-aliased
# edges, and the raster may sit a pixel lower. Measured: 2.3 grey levels on
# average; the PNG shifted by 3 pixels gives 5.6, by 6 pixels 13.7, a blank
# page 150, so the limit is 4.
pdftoppm -r 150 -singlefile "$work/pdf-150/slices.pdf" "$work/slices-from-pdf"  # PPM
compare() {  # compare PPM PNG LIMIT; Debian's Python, which has Debian's numpy (python3-nibabel's)
  /usr/bin/python3 - "$@" <<'PY'
import sys, zlib
import numpy as np

def ppm(path):
    data = open(path, 'rb').read()
    fields, at = [], 0
    while len(fields) < 4:  # P6, width, height, maxval, separated by whitespace
        while data[at:at + 1].isspace(): at += 1
        end = at
        while not data[end:end + 1].isspace(): end += 1
        fields.append(data[at:end]); at = end
    width, height = int(fields[1]), int(fields[2])
    return np.frombuffer(data[at + 1:at + 1 + width * height * 3], np.uint8).reshape(height, width, 3)

def png(path):  # 8-bit RGB or RGBA, any of the five row filters
    data = open(path, 'rb').read()
    at, idat, header = 8, b'', None
    while at < len(data):
        length = int.from_bytes(data[at:at + 4], 'big'); kind = data[at + 4:at + 8]
        body = data[at + 8:at + 8 + length]; at += 12 + length
        if kind == b'IHDR': header = body
        elif kind == b'IDAT': idat += body
    width, height = int.from_bytes(header[0:4], 'big'), int.from_bytes(header[4:8], 'big')
    channels = {2: 3, 6: 4}[header[9]]
    raw = zlib.decompress(idat); stride = width * channels
    out = np.zeros((height, stride), np.int32); previous = np.zeros(stride, np.int32)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        if kind == 0: cur = row
        elif kind == 2: cur = (row + previous) % 256
        else:
            cur = np.zeros(stride, np.int32)
            for i in range(stride):
                a = cur[i - channels] if i >= channels else 0
                b = previous[i]; c = previous[i - channels] if i >= channels else 0
                if kind == 1: p = a
                elif kind == 3: p = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (row[i] + p) % 256
        out[y] = cur; previous = cur
    return out.reshape(height, width, channels)[:, :, :3].astype(np.uint8)

def blocks(image, k=6):
    h, w, c = image.shape
    return image[:h // k * k, :w // k * k].reshape(h // k, k, w // k, k, c).mean(axis=(1, 3))

a, b = ppm(sys.argv[1]).astype(float), png(sys.argv[2]).astype(float)
if a.shape != b.shape:
    print('sizes differ:', a.shape, b.shape); sys.exit(1)
mean = np.abs(blocks(a) - blocks(b)).mean()
print(f'mean difference of 6 x 6 blocks {mean:.2f} grey levels (limit {sys.argv[3]})')
sys.exit(0 if mean < float(sys.argv[3]) else 1)
PY
}
check "slices.pdf drawn by poppler is slices.png (blocks differ by under 4 grey levels)" \
  compare "$work/slices-from-pdf.ppm" "$work/png-150/slices.png" 4

# SVG: the nominal size in points, one raster of 1.5 times the default
# pixels, and every text as one outline: 15 captions, 60 orientation letters
# (4 per slice) and 4 legend items, in a file an XML parser reads.
svg_structure() {
  python3 - "$1" <<'PY'
import sys
import xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
ns = '{http://www.w3.org/2000/svg}'
images = [e for e in root.iter(ns + 'image')]
paths = [e for e in root.iter(ns + 'path')]
print(root.get('width'), root.get('height'), [(i.get('width'), i.get('height')) for i in images], len(paths), 'paths')
ok = (root.get('width'), root.get('height')) == ('864pt', '576pt') and \
     [(i.get('width'), i.get('height')) for i in images] == [('1800', '1200')] and len(paths) == 79
sys.exit(0 if ok else 1)
PY
}
check "slices.svg: 864 x 576 pt, one 1800 x 1200 raster, its 79 texts as outlines" svg_structure "$work/svg-150/slices.svg"

# Bad choices are refused before anything is written.
expect_error "an unknown figure format" 2 "figure-format" "$work/r1" \
  "$DYNSUB" render --surface "$work/caudate/surface.vtp" --figure-format gif --out "$work/r1"
expect_error "a figure resolution below 50 dpi" 2 "figure-dpi" "$work/r2" \
  "$DYNSUB" render --surface "$work/caudate/surface.vtp" --figure-dpi 10 --out "$work/r2"
# Without pdftocairo (PATH emptied) PDF is refused before anything is drawn,
# naming the package.
expect_error "PDF without pdftocairo" 1 "poppler-utils" "$work/r3" \
  env PATH=/nonexistent "$DYNSUB" render --surface "$work/caudate/surface.vtp" --figure-format pdf --out "$work/r3"
check "no temporary file left" test -z "$(find "$work" -name '.tmp*' -print -quit)"

echo "$failures failure(s)"
test "$failures" -eq 0
