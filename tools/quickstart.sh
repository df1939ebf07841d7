#!/usr/bin/env bash
# README command 1: install what is missing, build, and run the main job on the bundled multi-tasking sample:
# simulate the six ball-bar runs of seed 000 on a machine with known deviations, identify the deviations, and
# print them next to the truth.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
ninja -C build -j2 cnccomp
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
M=samples/machines/multitasking.xml P=samples/plans/multitasking-six-circles.xml T=samples/deviations/multitasking-truth.csv
echo; echo "== simulate: six ball-bar runs of seed 000 section 5.3 on the erroneous machine (noise 0.1 um)"
./build/cnccomp simulate --machine $M --plan $P --deviations $T --noise-um 0.1 --seed 1 --out "$out/traces"
echo; echo "== identify (closed form, seed 000 eq. (17)-(28))"
./build/cnccomp identify --method closed-form --machine $M --traces "$out/traces" --plan $P --out "$out/closed-form.csv" >/dev/null
./build/cnccomp compare --machine $M --truth $T --estimate "$out/closed-form.csv"
echo; echo "== verify: the six runs on the true machine, as programmed and compensated with the identified set"
./build/cnccomp verify --machine $M --plan $P --truth $T --identified "$out/closed-form.csv"
