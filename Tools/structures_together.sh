#!/usr/bin/env bash
# Four basal-ganglia structures per hemisphere segmented together
# (`dynsub segment` with four --landmarks) against the same structures alone
# (report.json's "alone": each structure's first segmentation, as a separate
# run gives it): on Colin27 and on realistic single-scan subjects made from it
# (`dynsub subject`, seeds 1-3 or SEEDS, no thick slices), 36 clicks per structure on 6
# coronal slices made from each image's own labels. Prints, per run, each
# structure's Dice alone and in dseg.nii.gz, then the mean change, the worst
# and how many are lower. OPTIONS are added to every segment run
# (OPTIONS="--barrier-stiffness 0": the structures joined without the barrier).
# Usage: [SEEDS="4 5 6"] [OPTIONS="..."] [DYNSUB=BINARY] Tools/structures_together.sh [WORKDIR]
# (from the repository; build first; DYNSUB is build/bin/dynsub unless given)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
dynsub=${DYNSUB:-$root/build/bin/dynsub}
templates=/usr/share/mricron/templates
work=${1:-$(mktemp -d)}
mkdir -p "$work"
run() {  # run NAME IMAGE LABELS
  local name=$1 image=$2 labels=$3 side landmarks values i n
  for side in left right; do
    if [ $side = left ]; then values=(71 73 75 77); else values=(72 74 76 78); fi
    landmarks=() i=0
    for n in caudate putamen pallidum thalamus; do
      python3 "$root/Tools/landmarks_from_labels.py" "$labels" "${values[$i]}" coronal 6 6 \
        "$work/$name/${n}_$side.mrk.json" >/dev/null
      landmarks+=(--landmarks "$work/$name/${n}_$side.mrk.json")
      i=$((i + 1))
    done
    rm -rf "$work/$name/$side"
    "$dynsub" segment "$image" "${landmarks[@]}" --reference "$labels" --reference-label "${values[0]}" \
      --reference-label "${values[1]}" --reference-label "${values[2]}" --reference-label "${values[3]}" \
      ${OPTIONS:-} --no-figures --out "$work/$name/$side" >"$work/$name/$side.log" 2>&1
  done
}
mkdir -p "$work/colin27"
run colin27 "$templates/ch2.nii.gz" "$templates/aal.nii.gz"
for seed in ${SEEDS:-1 2 3}; do
  subject=$work/subject$seed
  [ -f "$subject/image.nii.gz" ] ||
    "$dynsub" subject "$templates/ch2.nii.gz" "$templates/aal.nii.gz" --seed $seed --set thick_fraction=0 \
      --out "$subject" >/dev/null
  run subject$seed "$subject/image.nii.gz" "$subject/labels.nii.gz"
done
python3 - "$work" <<'PY'
import glob, json, sys
changes = []
for path in sorted(glob.glob(sys.argv[1] + "/*/*/report.json")):
    report = json.load(open(path))
    if "structures" not in report:
        continue
    run = "/".join(path.split("/")[-3:-1])
    print("%s: voxels in two surfaces %d alone, %d with the barrier" %
          (run, report["shared_voxels_alone"], report["shared_voxels_together"]))
    for s in report["structures"]:
        alone, joint = s["alone"]["dice"], s["joint"]["dice"]
        changes.append(joint - alone)
        print("  %-16s Dice alone %.4f, in dseg %.4f (%+.4f)" % (s["name"], alone, joint, joint - alone))
print("%d structures: mean change %+.4f, worst %+.4f, best %+.4f, lower in %d" %
      (len(changes), sum(changes) / len(changes), min(changes), max(changes), sum(c < 0 for c in changes)))
PY
