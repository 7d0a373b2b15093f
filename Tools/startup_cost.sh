#!/usr/bin/env bash
# What each group of dynsub's shared libraries costs at start-up: empty
# programs linked to all of dynsub's libraries, then to fewer groups, each
# timed from the shell's clock (median of ROUNDS, taking turns):
#   Tools/startup_cost.sh [BUILD_DIR [ROUNDS]]
# (BUILD_DIR build and ROUNDS 9 unless given). The program does nothing, so
# its time is the loader's work (mapping, relocating) and the libraries'
# static initializers, as for `dynsub --version`.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
rounds=${2:-9}
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [BUILD_DIR [ROUNDS >= 1]]" >&2; exit 2; }
[ -x "$build/bin/dynsub" ] || { echo "$build/bin/dynsub is missing (build it first)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo 'int main(void) { return 0; }' >"$work/empty.c"
needed=$(readelf -d "$build/bin/dynsub" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p')

# program NAME DROPPED: an empty program linked to dynsub's libraries but
# those matching the extended regular expression DROPPED.
names=()
program() {
  local libs
  libs=$(grep -vE "$2" <<<"$needed" | sed 's/^/-l:/' | tr '\n' ' ')
  # shellcheck disable=SC2086
  cc "$work/empty.c" -o "$work/$1" -Wl,--no-as-needed -L"$build/lib" -Wl,-rpath,"$build/lib" $libs
  names+=("$1")
}
program "all of dynsub's" '^$'
program "without VTK's rendering" 'libvtk(Charts|Interaction|IOExport|Rendering|IOGeometry)|libGLX|libX11'
program "without VTK" 'libvtk|libGLX|libX11'
program "without VTK, CHOLMOD" 'libvtk|libGLX|libX11|libcholmod'
program "without VTK, CHOLMOD, ITK" 'libvtk|libGLX|libX11|libcholmod|libDynSub'
for ((r = 0; r < rounds; ++r)); do
  for name in "${names[@]}"; do
    start=$(date +%s%N)
    "$work/$name"
    end=$(date +%s%N)
    echo "$(( (end - start) / 1000 ))" >>"$work/$name.times"
  done
done
for name in "${names[@]}"; do
  sort -n "$work/$name.times" | awk -v name="$name" -v libraries="$(ldd "$work/$name" | wc -l)" \
    '{ t[NR] = $1 } END { printf "%-28s %3d libraries, median %5.1f ms\n", name, libraries, t[int(NR / 2) + 1] / 1e3 }'
done
