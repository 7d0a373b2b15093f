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
summary() {  # summary NAME LABELMAP TITLE
  local times
  times=$(cut -d' ' -f1 "$work/$1.times" | sort -n)
  local median low high kb
  median=$(echo "$times" | sed -n "$(( (rounds + 1) / 2 ))p")
  low=$(echo "$times" | head -1) high=$(echo "$times" | tail -1)
  kb=$(cut -d' ' -f2 "$work/$1.times" | sort -n | tail -1)
  printf "%-34s median %.3f s (%.3f-%.3f), peak %d MB, Dice %s\n" "$3" \
    "$(echo "$median / 1000000" | bc -l)" "$(echo "$low / 1000000" | bc -l)" "$(echo "$high / 1000000" | bc -l)" \
    $((kb / 1024)) "$(dice "$2")"
}
echo "$rounds rounds taking turns:"
summary dynsub "$work/dynsub/labelmap.nii.gz" "dynsub segment (whole command)"
summary itk "$work/itk.nii.gz" "ITK threshold level set (command)"
