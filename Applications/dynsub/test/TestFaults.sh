#!/usr/bin/env bash
# Faults a batch job meets (Documentation/Reliability.md): a run killed at
# random moments, a full disk, a directory that cannot be written, and two
# runs writing to one --out at once. After each: no partial file and no
# incomplete output set; a killed run's temporary files are swept by the rerun. Needs DYNSUB and DATA, Colin27
# (mricron-data), and flock (util-linux). The full disk and the read-only
# directory are small tmpfs mounts when this runs as root; otherwise a file
# size limit (ulimit -f) and a directory without write permission stand in.
set -u
work=$(mktemp -d)
mounts=()
cleanup() {
  for m in "$work/full" "${mounts[@]}"; do umount "$m" 2>/dev/null; done
  chmod -R u+w "$work" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
source "$(dirname "${BASH_SOURCE[0]}")/Checks.sh"
require_colin27

segment=("$DYNSUB" segment "$templates/ch2.nii.gz" --landmarks "$DATA/Landmarks/caudate_left.mrk.json" --no-figures)
temporaries() { find "$1" -name '.tmp-*' 2>/dev/null | wc -l; }
# --- one whole run: its duration and its output set -------------------------
start=$(date +%s%N)
"${segment[@]}" --out "$work/whole" >"$work/whole.log" 2>&1
check "a whole segment run succeeds" test $? -eq 0
duration_ms=$((($(date +%s%N) - start) / 1000000))
expected=$(ls -A "$work/whole" | sort | tr '\n' ' ')
echo "a whole run: ${duration_ms} ms, writes: $expected"
check "a whole run leaves no temporary file" test "$(temporaries "$work/whole")" -eq 0
check "nor the folder it was written in" test -z "$(find "$work" -maxdepth 1 -name '.tmp-*')"

# --- killed at 20 random moments (SIGKILL) ---------------------------------
# Odd kills at moments from 0 to 1.1 times a whole run, even ones in its
# last fifth, where the files are written; the directory is removed before
# each run. A kill leaves either no output or the whole set, never part of
# it; its temporary files (.tmp-<pid>-<name>) stay until the next run of the
# same output sweeps them (AtomicOutput.h).
RANDOM=2026
complete=0 absent=0 broken=0 leftover=0
outputs() { ls -A "$1" 2>/dev/null | grep -v '^\.tmp-' | sort | tr '\n' ' '; }
# What a killed run leaves: the folder its new --out was written in
# (.tmp-<pid>-killed, beside it; OutputSet.h), or temporary files in --out.
leftovers() { { find "$work" -maxdepth 1 -name '.tmp-*-killed'; find "$work/killed" -name '.tmp-*' 2>/dev/null; } | wc -l; }
for i in $(seq 1 20); do
  rm -rf "$work/killed"
  if [ $((i % 2)) -eq 1 ]; then
    delay_ms=$((RANDOM % (duration_ms * 11 / 10 + 1)))
  else
    delay_ms=$((duration_ms * 8 / 10 + RANDOM % (duration_ms * 3 / 10 + 1)))
  fi
  "${segment[@]}" --out "$work/killed" >/dev/null 2>&1 &
  pid=$!
  sleep "$(awk -v ms="$delay_ms" 'BEGIN { printf "%.3f", ms / 1000 }')"
  kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  [ "$(leftovers)" -ne 0 ] && leftover=$((leftover + 1))
  if [ -z "$(outputs "$work/killed")" ]; then
    absent=$((absent + 1))
  elif [ "$(outputs "$work/killed")" = "$expected" ]; then
    complete=$((complete + 1))
  else
    broken=$((broken + 1))
    echo "kill $i at ${delay_ms} ms left an incomplete set: $(outputs "$work/killed")"
  fi
  # The rerun of a killed job: it completes and sweeps the killed run's temporaries.
  if [ "$(leftovers)" -ne 0 ]; then
    "${segment[@]}" --out "$work/killed" >/dev/null 2>&1
    check "kill $i: the rerun succeeds" test $? -eq 0
    check "kill $i: the rerun leaves the whole set" test "$(outputs "$work/killed")" = "$expected"
    check "kill $i: the rerun sweeps the killed run's temporaries" test "$(leftovers)" -eq 0
  fi
done
echo "20 kills: $absent before any output, $complete after the whole set, $broken incomplete," \
  "$leftover leaving temporaries for the rerun"
check "no kill leaves an incomplete output set" test "$broken" -eq 0

# --- a full disk -------------------------------------------------------------
# expect_refusal NAME FRAGMENT DIR COMMAND...: exit 1, a message naming the
# problem, and nothing left in DIR.
expect_refusal() {
  local name=$1 fragment=$2 dir=$3; shift 3
  "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  check "$name: exit code 1 (got $rc)" test "$rc" -eq 1
  check "$name: the message says '$fragment'" grep -q -- "$fragment" "$work/stderr"
  cat "$work/stderr"
  check "$name: nothing is left in $dir" test -z "$(ls -A "$dir")"
}
mkdir -p "$work/readonly"
# full_disk NAME KIB FRAGMENT COMMAND... (COMMAND writes into $work/full): on
# a tmpfs of KIB KiB as root, else under a file size limit of KIB KiB (with
# SIGXFSZ ignored, a write beyond it fails as on a full disk).
full_disk() {
  local name=$1 kib=$2 fragment=$3; shift 3
  mkdir -p "$work/full"
  if [ "$(id -u)" -eq 0 ] && mount -t tmpfs -o size="${kib}k" tmpfs "$work/full" 2>/dev/null; then
    expect_refusal "$name (a $kib KiB tmpfs)" "$fragment: No space left on device" "$work/full" "$@"
    umount "$work/full"
  else
    expect_refusal "$name (a $kib KiB file size limit)" "$fragment" "$work/full" \
      bash -c 'trap "" XFSZ; ulimit -f "$0"; exec "$@"' "$kib" "$@"
  fi
  rm -rf "$work/full"
}
full_disk "segment on a full disk" 64 "out/surface.vtp: could not be written" \
  "${segment[@]}" --out "$work/full/out"
# VTK's XML writer returned success when cut short: the cube's limit surface
# (about 450 KiB as .vtp) on 16 KiB.
full_disk "limit on a full disk" 16 "cube.vtp: could not be written" \
  "$DYNSUB" limit "$DATA/Meshes/cube.obj" --samples-per-face 8 --out "$work/full/cube.vtp"

# --- a directory that cannot be written --------------------------------------
if [ "$(id -u)" -eq 0 ] && mount -t tmpfs -o size=1m,ro tmpfs "$work/readonly" 2>/dev/null; then
  mounts+=("$work/readonly")
else
  chmod a-w "$work/readonly"
fi
expect_refusal "a read-only directory" "is not writable" "$work/readonly" \
  "${segment[@]}" --out "$work/readonly/out"

# --- two runs writing to one --out at once -----------------------------------
# The hat's springs without their own stiffness, so that --stiffness sets it.
awk '!/^#/ && NF { print $1, $2, $3 }' "$DATA/Deform/sheet_hat.springs" >"$work/hat.springs"
deform() {  # deform STIFFNESS OUT
  "$DYNSUB" deform "$DATA/Meshes/sheet.obj" --springs "$work/hat.springs" --fix-boundary \
    --stiffness "$1" --out "$2"
}
deform 5 "$work/solo5" >/dev/null 2>&1
deform 40 "$work/solo40" >/dev/null 2>&1
check "deform with stiffness 5 and 40 give different surfaces" \
  bash -c '! cmp -s "$1/control_mesh.obj" "$2/control_mesh.obj"' _ "$work/solo5" "$work/solo40"
# While another process holds the directory's lock, a run waits to write.
mkdir -p "$work/shared"
flock "$work/shared" sleep 4 &
holder=$!
sleep 0.5
deform 5 "$work/shared" >/dev/null 2>"$work/waiting.log" &
waiter=$!
for _ in $(seq 1 30); do grep -q "waiting for another run" "$work/waiting.log" && break; sleep 0.1; done
check "a run waits while another holds the directory" grep -q "waiting for another run" "$work/waiting.log"
check "and has written nothing yet" test -z "$(ls -A "$work/shared")"
wait "$holder"
wait "$waiter"
check "then writes its whole set" cmp -s "$work/shared/control_mesh.obj" "$work/solo5/control_mesh.obj"
# Ten races: the set that stays is one run's, whole.
mixed=0
for i in $(seq 1 10); do
  rm -rf "$work/race"
  deform 5 "$work/race" >/dev/null 2>&1 &
  first=$!
  deform 40 "$work/race" >/dev/null 2>&1 &
  second=$!
  wait "$first" "$second"
  stiffness=$(sed -n 's/^ *"default_spring_stiffness": \([0-9.]*\).*/\1/p' "$work/race/report.json")
  solo="$work/solo${stiffness%.*}"
  if ! cmp -s "$work/race/control_mesh.obj" "$solo/control_mesh.obj" ||
    ! cmp -s "$work/race/surface.vtp" "$solo/surface.vtp" || [ "$(temporaries "$work/race")" -ne 0 ] ||
    [ -n "$(find "$work" -maxdepth 1 -name '.tmp-*-race')" ]; then
    mixed=$((mixed + 1))
    echo "race $i: report.json says stiffness '$stiffness', the other files do not match it"
  fi
done
check "ten races of two runs: every set left is one run's, whole" test "$mixed" -eq 0

echo "$failures check(s) failed"
[ "$failures" -eq 0 ]
