#!/usr/bin/env bash
# README command 1, the main job: the whole calibration loop on the bundled multi-tasking sample, step by step as
# you would run it on a real machine with a ball bar. A simulation stands in for the machine and the ball bar in step
# 2 (the measurement) and in step 7 (verify --truth: where you would load the files and measure again; without --truth
# verify predicts on the identified machine, as emit does in step 5); every command is the one you would type.
#
#   1 testprog  the NC programs that make the plan's six ball-bar runs
#   2 simulate  running them with a ball bar: the instrument's time-sampled files, CW then CCW  (the stand-in)
#   3 identify  the machine's deviations by least squares, with the HTML report
#   4 map       the volumetric error of the identified machine
#   5 emit      the compensation files of every controller (each prints the residual it predicts)
#   6 correct   a part program, and the test programs themselves
#   7 verify    the test programs through each controller's files and through the corrected programs, on the
#               simulated real machine, with an HTML report each
#
# Every output stays in one folder (default out/quickstart/, emptied first; ignored by git); the last lines print the
# before/after summary, a "!!!" line for every compensation that leaves the machine worse than none, and where the
# reports are. emit's WARNING lines are printed as they come.
#
# usage: bash tools/quickstart.sh [--out DIR] [--no-build] [--cnccomp PATH]
#   --no-build   skip installing packages and building (the test tests/test_quickstart.cpp runs the chain this way)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=$root/out/quickstart build=1 cnccomp=$root/build/cnccomp
while (($#)); do
  case "$1" in
    --out) out=$(realpath -m "$2"); shift 2 ;;
    --no-build) build=0; shift ;;
    --cnccomp) cnccomp=$(realpath -m "$2"); shift 2 ;;
    *) echo "usage: bash tools/quickstart.sh [--out DIR] [--no-build] [--cnccomp PATH]" >&2; exit 2 ;;
  esac
done
# The output folder is emptied first: only a folder this script made (it holds .quickstart) or an empty one.
if [ -e "$out" ] && { [ ! -d "$out" ] || { [ -n "$(ls -A "$out")" ] && [ ! -e "$out/.quickstart" ]; }; }; then
  echo "quickstart: $out exists and was not made by this script; give another --out" >&2
  exit 2
fi
cd "$root"
out=${out#"$root"/}  # relative to the repository when inside it (shorter to read)
if ((build)); then
  bash tools/deps.sh
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCNCCOMP_UNITY=ON >/dev/null
  ninja -C build -j2 cnccomp
fi
cnccomp() { "$cnccomp" "$@"; }

M=samples/machines/multitasking.xml                  # the machine: w-C'bZYXB(C1)-t of the multi-tasking paper
P=samples/plans/multitasking-six-circles-recorded.xml  # six ball-bar runs, recorded time-sampled CW then CCW
T=samples/deviations/multitasking-truth.csv          # the real machine's deviations: known to the simulation only
PART=samples/gcode/multitasking-5axis.ngc            # a 5-axis part program
controllers=(fanuc-30i generic heidenhain-tnc isg linuxcnc siemens-840d)
rm -rf "$out"
mkdir -p "$out"
echo "outputs of tools/quickstart.sh (this folder is emptied when it runs again)" > "$out/.quickstart"
mkdir -p "$out"/{1-testprog,2-ballbar,3-identify,4-map,5-emit,6-correct/testprog,7-verify}
step() { echo; echo "== $*"; }

step "1 testprog: the NC programs of the six runs (LinuxCNC; feed and overshoot as the plan records them)"
cnccomp testprog --machine $M --plan $P --dialect linuxcnc --feed 1000 --overshoot 4 --out "$out/1-testprog"

step "2 simulate: the programs run with a ball bar on the real machine (0.2 um noise): one instrument file per run"
cnccomp simulate --machine $M --plan $P --deviations $T --noise-um 0.2 --seed 1 --instrument time --out "$out/2-ballbar"

step "3 identify: least squares on every sample of the imported files (report: 3-identify/report.html)"
D="$out/3-identify/deviations.csv"
cnccomp identify --machine $M --plan $P --traces "$out/2-ballbar" --out "$D" --report "$out/3-identify/report.html" \
  --report-controllers "$(IFS=,; echo "${controllers[*]}")" | sed -n '/^ISO 230-4/,$p'
cnccomp compare --machine $M --truth $T --estimate "$D" | tail -1

step "4 map: tool-tip error of the identified machine, X and Y over +-200 mm at B = 30 deg, tool length 360 mm"
cnccomp map --machine $M --deviations "$D" --grid "X=-200:200:20 Y=-200:200:20 Z=0 B=30 C=0" --tool-length 360 \
  --out "$out/4-map/map.csv" --svg "$out/4-map/map.svg" | tail -1

step "5 emit: compensation files for every controller, with the residual they leave on the identified machine"
for c in "${controllers[@]}"; do
  cnccomp emit --controller $c --machine $M --deviations "$D" --plan $P --out "$out/5-emit/$c" > "$out/5-emit/$c.txt"
  echo "$c: $(grep '^predicted residual' "$out/5-emit/$c.txt" | sed 's/.*: largest/largest/')"
  grep 'WARNING' "$out/5-emit/$c.txt" | sed "s/^/$c: /" || true  # every warning of emit, not only in 5-emit/<c>.txt
done

step "6 correct: the part program, and each test program with its tool length (from its header)"
cnccomp correct --machine $M --deviations "$D" --in $PART --out "$out/6-correct/$(basename $PART)" \
  --tool-length H1=100 --work-offset G54=0,0,0 | grep -E '^(corrected|largest)'
for f in "$out"/1-testprog/TP*.ngc; do
  L=$(sed -n 's/.*cnccomp correct --tool-length \([0-9.]*\).*/\1/p' "$f")
  cnccomp correct --machine $M --deviations "$D" --in "$f" --out "$out/6-correct/testprog/$(basename "$f")" --tool-length "$L" \
    > /dev/null
done
echo "corrected $(ls "$out"/6-correct/testprog | wc -l) test programs into 6-correct/testprog"

step "7 verify: the test programs through what you would load, on the real machine (simulation with the truth)"
verify() {  # verify NAME COMPENSATION [options]: report and JSON in 7-verify/NAME
  # Exit status 1 (a gate failed, or the compensation makes the machine worse: the first line says so) is a result
  # to show, not a reason to stop; 2 (bad input) stops.
  local name=$1 comp=$2 status=0; shift 2
  cnccomp verify --machine $M --plan $P --compensation "$comp" --truth $T --report "$out/7-verify/$name/report.html" \
    --json "$out/7-verify/$name/verify.json" "$@" > "$out/7-verify/$name.txt" 2>&1 || status=$?
  if ((status > 1)); then cat "$out/7-verify/$name.txt" >&2; exit "$status"; fi
  grep -E '^(COMPENSATION MAKES|residual|verification passed)|error: verification failed: [^C]' "$out/7-verify/$name.txt" |
    sed "s/^/$name: /"
}
verify ideal "$D" --max-residual-um 1           # a perfect TCP controller with the identified set: gate at 1 um
verify corrected-programs "$out/6-correct/testprog" --max-residual-um 1
for c in "${controllers[@]}"; do verify $c "$out/5-emit/$c"; done

step "summary: largest ball-bar dL span of the six runs and largest tool-tip error, before -> after compensation (um)"
{
  printf '%-19s %-18s %-18s %-18s %-5s %s\n' compensation "span predicted" "span verified" "tool tip verified" left report
  for name in ideal corrected-programs "${controllers[@]}"; do
    txt="$out/7-verify/$name.txt" predicted="-"
    [ -f "$out/5-emit/$name.txt" ] && predicted=$(sed -n 's/.*largest span \([0-9.]*\) um (before \([0-9.]*\) um).*/\2 -> \1/p' \
      "$out/5-emit/$name.txt")
    verified=$(sed -n 's/^residual (largest span after compensation): \([0-9.]*\) um (before: \([0-9.]*\) um)/\2 -> \1/p' "$txt")
    tip=$(sed -n 's/^  max \([0-9.]*\) -> \([0-9.]*\) um, RMS.*/\1 -> \2/p' "$txt")
    left=$(sed -n '/^deviations left by the compensation (/,/^residual/p' "$txt" | grep -c '^  ' || true)
    printf '%-19s %-18s %-18s %-18s %-5s %s\n' "$name" "$predicted" "$verified" "${tip:--}" "$left" "$out/7-verify/$name/report.html"
  done
  echo
  # A banner line for every compensation that leaves the real machine worse than none (verify's first line).
  for name in ideal corrected-programs "${controllers[@]}"; do
    banner=$(grep -m1 '^COMPENSATION MAKES THE MACHINE WORSE' "$out/7-verify/$name.txt" || true)
    [ -z "$banner" ] || echo "!!! $name: $banner (7-verify/$name.txt)"
  done
  echo "predicted: what cnccomp emit says the files leave on the identified machine; verified: cnccomp verify on the"
  echo "simulated real machine; left: deviations the controller's files cannot hold (named with the reason in"
  echo "7-verify/<name>.txt and in the report). Identification report: $out/3-identify/report.html"
  echo "every output: $out/"
} | tee "$out/summary.txt"
