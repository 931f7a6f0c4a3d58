#!/usr/bin/env bash
# Install what is missing, build, and run the full test suite with no display.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash .ci/setup.sh
bash .ci/build.sh
cd build
env -u DISPLAY -u WAYLAND_DISPLAY ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)"
