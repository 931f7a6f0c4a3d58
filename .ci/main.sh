#!/usr/bin/env bash
# The main job: install what is missing, build, run the default scene into out/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash .ci/setup.sh
bash .ci/build.sh
./build/furrow demo --out out
