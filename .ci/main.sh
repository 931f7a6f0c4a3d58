#!/usr/bin/env bash
# The main job: install what is missing, build, run the default scene (a plate intruding a bed,
# paper case 2) at dx 5 mm, fine enough for its shear bands to read as in the paper's figures
# (~2 min of solver time on 2 cores; the template's 10 mm preview is what the tests run), into
# out/: forces.csv, OpenVDB frames, MP4 movies with a poster PNG each.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash .ci/setup.sh
bash .ci/build.sh
# a headless rendering check image (out/demo/test_scene*.png)
./build/furrow demo --out out
# never overwrite an earlier run: a second run gets a time-stamped directory
out=out/plate_intrusion
if [ -e "$out" ]; then out="out/plate_intrusion-$(date +%Y%m%d-%H%M%S)"; fi
./build/furrow run scenes/plate_intrusion.json --set domain.dx_m=0.005 --out "$out"
