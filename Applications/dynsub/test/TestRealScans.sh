#!/usr/bin/env bash
# Shape recovery from real data the fits were never tuned on, one genus each:
# CGAL's sample data (Debian package libcgal-demo): the bear (13 826 points,
# genus 0, automatic initial model), the kitten range scan (5 210 points,
# genus 1) and the figure eight (315 points, genus 2), the last two from the
# control meshes in Data/Meshes. Each must reach the papers' tolerance,
# max_error_percent <= 1, with several times fewer control vertices than points.
# Then the kitten and the bear as a worse scanner would take them
# (Tools/corrupt_cloud.py: 0.3 % noise of the bounding box's diagonal per
# coordinate, 3 % outliers in its box): each fit must find most outliers,
# stop by the bias rule, and end within 1 % of the clean scan's points
# (ShapeRecovery.h). And CGAL's meshed cube and eight, their vertices measured
# as a scan's points: the cube's sharp edges and the eight's sparsely sampled
# handles must not be taken for noise; and the pig, a clean mesh whose
# scatter alone could be a scan's noise, fitted from its vertices as exact.
# Needs DYNSUB (the executable) and DATA.
set -u
archive=/usr/share/doc/libcgal-dev/data.tar.gz
if [ ! -f "$archive" ]; then
  echo "FAILED: $archive is missing (install the Debian package libcgal-demo; ./run does)"
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xzf "$archive" -C "$work" data/meshes/bear.off data/points_3/kitten.xyz data/meshes/eight.off \
  data/meshes/cube-meshed.off data/meshes/pig.off

source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
value() {  # value REPORT KEY: a top-level number from report.json
  sed -n "s/^  \"$2\": \([-0-9.e+]*\),\{0,1\}$/\1/p" "$1"
}
# fit_scan NAME POINTS GENUS MAX_CONTROL_VERTICES MAX_FREE_POINTS FIT_OPTIONS...
fit_scan() {
  local name=$1 points=$2 genus=$3 max_vertices=$4 max_free=$5; shift 5
  "$DYNSUB" fit "$points" --out "$work/$name" "$@" >"$work/$name.log" 2>&1
  check "$name: fit succeeds" test $? -eq 0
  cat "$work/$name.log"
  local report=$work/$name/report.json
  [ -f "$report" ] || return
  local error vertices
  error=$(value "$report" max_error_percent)
  vertices=$(value "$report" control_vertices)
  check "$name: max_error_percent $error <= 1" awk -v e="$error" 'BEGIN { exit !(e != "" && e <= 1.0) }'
  check "$name: genus $genus" test "$(value "$report" genus)" = "$genus"
  check "$name: $vertices control vertices <= $max_vertices" test "$vertices" -le "$max_vertices"
  local free
  free=$(value "$report" free_control_points)
  check "$name: $free free control points <= $max_free" test "$free" -le "$max_free"
}

# Local refinement (Simulation.h) frees points only where the bear's level 1
# is refused: at least 30 % fewer than global refinement's 1538 (531 measured).
fit_scan bear "$work/data/meshes/bear.off" 0 1538 1076
fit_scan kitten "$work/data/points_3/kitten.xyz" 1 772 772 --init "$DATA/Meshes/kitten_genus1.obj"
fit_scan eight "$work/data/meshes/eight.off" 2 48 48 --init "$DATA/Meshes/eight_genus2.obj"

tools=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../../Tools" && pwd)
nested() {  # nested REPORT KEY.KEY
  python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): r = r[k]
print(r)' "$1" "$2"
}

# A clean CAD part's sharp edges are not noise: CGAL's meshed cube (866
# points, most within a neighbourhood of an edge), its vertices measured as a
# scan's points would be (--noise measure), is fitted to the 0.1 % asked by
# the papers' rule, not stopped early by the bias rule as a noisy scan would
# be (ScanNoise.h).
"$DYNSUB" fit "$work/data/meshes/cube-meshed.off" --noise measure --tolerance 0.1 --no-figures --out "$work/cube" \
  >"$work/cube.log" 2>&1
check "cube: fit succeeds" test $? -eq 0
cat "$work/cube.log"
if [ -f "$work/cube/report.json" ]; then
  check "cube: not taken for noisy" test "$(nested "$work/cube/report.json" data_noise.noise_limited)" = False
  cube_error=$(value "$work/cube/report.json" max_error_percent)
  check "cube: max_error_percent $cube_error <= 0.1" awk -v e="$cube_error" 'BEGIN { exit !(e != "" && e <= 0.1) }'
fi
# The eight's 315 points, measured as a scan's, sample its handles too
# sparsely for the quadrics: their scatter grows with the neighbourhood, so
# it is shape, not noise (ScanNoise.h), and the fit meets the tolerance by
# the papers' rule rather than stopping by the bias rule 2.9 % from its points.
# The default start is a sphere, which spans the eight's two holes: the fit
# says so (closedMeshGenus, PointCloudIO.h).
"$DYNSUB" fit "$work/data/meshes/eight.off" --noise measure --no-figures --out "$work/eight_auto" \
  >"$work/eight_auto.log" 2>&1
check "eight, default start: fit succeeds" test $? -eq 0
cat "$work/eight_auto.log"
if [ -f "$work/eight_auto/report.json" ]; then
  check "eight, default start: not taken for noisy" \
    test "$(nested "$work/eight_auto/report.json" data_noise.noise_limited)" = False
  eight_error=$(value "$work/eight_auto/report.json" max_error_percent)
  check "eight, default start: max_error_percent $eight_error <= 1" \
    awk -v e="$eight_error" 'BEGIN { exit !(e != "" && e <= 1.0) }'
  check "eight, default start: its genus 2 named" test "$(value "$work/eight_auto/report.json" data_genus)" = 2
  check "eight, default start: warned that the model's genus is not the scan's" \
    grep -q "is a closed mesh of genus 2 but the initial model has genus 0" "$work/eight_auto.log"
fi
# A mesh's vertices are exact by default: the pig's 468 vertices scatter about
# their neighbours' quadrics 1.4-fold more with 20 neighbours than with 12, under
# the growth that marks shape (kShapeGrowth), so measured as a scan's points
# they read as noise and the fit stops by the bias rule 3.4 % from them. As a
# mesh, none is set aside and the fit meets the tolerance.
"$DYNSUB" fit "$work/data/meshes/pig.off" --no-figures --out "$work/pig" >"$work/pig.log" 2>&1
check "pig: fit succeeds" test $? -eq 0
cat "$work/pig.log"
if [ -f "$work/pig/report.json" ]; then
  check "pig: vertices taken as exact" test "$(nested "$work/pig/report.json" data_noise.mesh_vertices_exact)" = True
  check "pig: no outliers" test "$(nested "$work/pig/report.json" data_noise.outliers)" = 0
  pig_error=$(value "$work/pig/report.json" max_error_percent)
  check "pig: max_error_percent $pig_error <= 1" awk -v e="$pig_error" 'BEGIN { exit !(e != "" && e <= 1.0) }'
fi
# fit_noisy NAME CLEAN MIN_OUTLIERS FIT_OPTIONS...: the scan corrupted, fitted
# and measured against its clean points.
fit_noisy() {
  local name=$1 clean=$2 min_outliers=$3; shift 3
  python3 "$tools/corrupt_cloud.py" "$clean" "$work/$name.xyz" --noise 0.3 --outliers 3 --seed 1
  "$DYNSUB" fit "$work/$name.xyz" --reference "$clean" --no-figures --out "$work/$name" "$@" >"$work/$name.log" 2>&1
  check "$name: fit succeeds" test $? -eq 0
  cat "$work/$name.log"
  local report=$work/$name/report.json
  [ -f "$report" ] || return
  local reference outliers
  reference=$(nested "$report" reference.max_error_percent)
  outliers=$(nested "$report" data_noise.outliers)
  check "$name: $reference % from the clean scan <= 1" awk -v e="$reference" 'BEGIN { exit !(e <= 1.0) }'
  check "$name: stopped by the bias rule (max error above 1 %, bias within it)" python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
sys.exit(0 if r["data_noise"]["noise_limited"] and r["max_error_percent"] > 1.0
         and r["data_noise"]["bias_percent"] <= 1.0 else 1)' "$report"
  check "$name: tolerance met" test "$(nested "$report" converged)" = True
  check "$name: $outliers outliers set aside >= $min_outliers" test "$outliers" -ge "$min_outliers"
}
# 3 % added (156 and 415); those within a few sigma of the surface cannot stand out.
fit_noisy noisy_kitten "$work/data/points_3/kitten.xyz" 100 --init "$DATA/Meshes/kitten_genus1.obj"
fit_noisy noisy_bear "$work/data/meshes/bear.off" 250

echo "$failures failure(s)"
test "$failures" -eq 0
