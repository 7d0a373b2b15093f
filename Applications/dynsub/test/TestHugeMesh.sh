#!/usr/bin/env bash
# A control mesh of 10^6 faces (a hostile size for a tool whose meshes have
# hundreds): a regular 1000 x 1000 quad torus (R = 3 mm, r = 1 mm), read,
# checked and evaluated by `dynsub limit` at one point per face. Every limit
# point must lie on the torus: a closed cubic B-spline ring of n points
# shrinks a circle by about (2 pi / n)^2 / 6 of its radius, 2.6e-5 mm for the
# 4 mm outer ring, so 1e-4 mm holds with margin. Needs DYNSUB and python3.
# (About 30 s and 3 GB.)
set -u
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"

python3 - "$work/torus.obj" <<'PY'
import math, sys
n = 1000
with open(sys.argv[1], "w") as out:
    for i in range(n):
        a = 2 * math.pi * i / n
        for j in range(n):
            b = 2 * math.pi * j / n
            r = 3 + math.cos(b)
            out.write("v %.9f %.9f %.9f\n" % (r * math.cos(a), r * math.sin(a), math.sin(b)))
    for i in range(n):
        for j in range(n):
            v = lambda p, q: (p % n) * n + (q % n) + 1
            out.write("f %d %d %d %d\n" % (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)))
PY
check "the torus has 10^6 faces" test "$(grep -c '^f ' "$work/torus.obj")" -eq 1000000

"$DYNSUB" limit "$work/torus.obj" --samples-per-face 1 --out "$work/limit.obj" >"$work/log" 2>&1
check "limit evaluates the 10^6-face mesh" test $? -eq 0
cat "$work/log"
points=$(grep -c '^v ' "$work/limit.obj")
check "one limit point per face corner: $points" test "$points" -eq 1000000
worst=$(awk '/^v / { d = sqrt((sqrt($2 * $2 + $3 * $3) - 3) ^ 2 + $4 * $4) - 1; if (d < 0) d = -d;
                     if (d > w) w = d; if (d != d) nan = 1 }
             END { if (nan) print "nan"; else printf "%.3g", w }' "$work/limit.obj")
echo "largest distance of a limit point from the torus: $worst mm"
check "every limit point lies on the torus (<= 1e-4 mm, got $worst)" \
  awk -v w="$worst" 'BEGIN { exit !(w != "nan" && w <= 1e-4) }'

echo "$failures check(s) failed"
[ "$failures" -eq 0 ]
