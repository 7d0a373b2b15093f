#!/usr/bin/env bash
# The whole `dynsub segment` command against ITK's threshold level set as a
# whole command (build/bin/ItkThresholdLevelSetCommand: ITK's reader, the
# filter on DynSub's region from DynSub's initial model, ITK's writer), on the
# caudate demo (Colin27, Data/Landmarks/caudate_left.mrk.json), taking turns
# so that both see the same machine load:
#   Tools/compare_segment_commands.sh [BUILD_DIR [ROUNDS]]
# (BUILD_DIR build and ROUNDS 9 unless given). Prints each command's median
# wall time and range (from the shell's clock around each run), its peak
# memory, and each labelmap's Dice against AAL's left caudate (label 71;
# nibabel, Debian's python3-nibabel). The filter alone against DynSub's segment() in one
# process is SegmentationComparison's head to head.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
rounds=${2:-9}
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [BUILD_DIR [ROUNDS >= 1]]" >&2; exit 2; }
image=/usr/share/mricron/templates/ch2.nii.gz
labels=/usr/share/mricron/templates/aal.nii.gz
landmarks=$here/Data/Landmarks/caudate_left.mrk.json
for program in dynsub SegmentationComparison ItkThresholdLevelSetCommand; do
  [ -x "$build/bin/$program" ] || { echo "$build/bin/$program is missing (build it first)" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/bin/SegmentationComparison" --write-initial "$work/initial.nii.gz" >/dev/null

# timed NAME COMMAND...: appends "microseconds peak_kb" to $work/NAME.times.
timed() {
  local name=$1; shift
  local start end
  start=$(date +%s%N)
  /usr/bin/time -f "%M" -o "$work/memory" "$@" >/dev/null 2>"$work/log" ||
    { echo "$name failed: $(tail -1 "$work/log")" >&2; exit 1; }
  end=$(date +%s%N)
  echo "$(( (end - start) / 1000 )) $(cat "$work/memory")" >>"$work/$name.times"
}
for ((r = 0; r < rounds; ++r)); do
  rm -rf "$work/dynsub"
  timed dynsub "$build/bin/dynsub" segment "$image" --landmarks "$landmarks" --no-figures --out "$work/dynsub"
  timed itk "$build/bin/ItkThresholdLevelSetCommand" "$image" "$work/initial.nii.gz" "$work/itk.nii.gz"
done
dice() {  # dice LABELMAP: against AAL's label 71
  /usr/bin/python3 -c '
import sys, nibabel
a = nibabel.load(sys.argv[1]).get_fdata() > 0
r = nibabel.load(sys.argv[2]).get_fdata() == 71
print("%.3f" % (2 * (a & r).sum() / (a.sum() + r.sum())))' "$1" "$labels"
}
summary() {  # summary NAME LABELMAP TITLE: the median (the upper middle for even ROUNDS, as
  # SegmentationComparison's) and range of the times, the peak memory, the Dice.
  sort -n "$work/$1.times" | awk -v title="$3" -v dice="$(dice "$2")" '{ t[NR] = $1; if ($2 > kb) kb = $2 }
    END { n = NR; printf "%-34s median %.3f s (%.3f-%.3f), peak %d MB, Dice %s\n", title,
          t[int(n / 2) + 1] / 1e6, t[1] / 1e6, t[n] / 1e6, kb / 1024, dice }'
}
echo "$rounds rounds taking turns:"
summary dynsub "$work/dynsub/labelmap.nii.gz" "dynsub segment (whole command)"
summary itk "$work/itk.nii.gz" "ITK threshold level set (command)"
