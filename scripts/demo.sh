#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# Builds and runs the Scree demo (examples/scree_demo.cpp) and shows its recording in the replay page:
#   1. installs missing Debian packages (scripts/install-deps.sh),
#   2. configures build/ in Release,
#   3. builds the scree_demo and scree (the command-line program) targets,
#   4. runs build/examples/scree_demo (extra arguments are passed to it), which prints its table and records its
#      combined scene to build/demo/scree_demo.screerec,
#   5. `scree view` writes build/demo/scree_demo.html, the page that replays it (docs/viewer.md); it is opened in
#      the desktop's browser when there is a display, and otherwise headless Chromium saves a screenshot of it at
#      t = 4 s to build/demo/scree_demo.png.
# Environment: SCREE_JOBS (parallel jobs, default: all cores), SCREE_BUILD_DIR (default: build).
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$SCREE_ROOT"
build_dir="${SCREE_BUILD_DIR:-build}"

step "Checking build dependencies"
bash scripts/install-deps.sh
echo "dependencies: ok"

step "Configuring $build_dir/ (Release)"
run cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DSCREE_BUILD_EXAMPLES=ON

step "Building scree_demo and scree"
run cmake --build "$build_dir" --target scree_demo scree_cli -j "$SCREE_JOBS"

step "Running the demo"
mkdir -p "$build_dir/demo"
recording="$build_dir/demo/scree_demo.screerec"
page="$build_dir/demo/scree_demo.html"
status=0
run "$build_dir/examples/scree_demo" "$@" --record "$recording" || status=$?

step "The replay page"
run "$build_dir/examples/scree/scree" view "$recording" -o "$page"
url="file://$(cd "$(dirname "$page")" && pwd)/$(basename "$page")"
if [[ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]] && command -v xdg-open >/dev/null 2>&1; then
  xdg-open "$url" >/dev/null 2>&1 || true
  echo "opened $url"
elif command -v chromium >/dev/null 2>&1; then
  shot="$build_dir/demo/scree_demo.png"
  # No display: headless Chromium (software WebGL) renders the page paused at t = 4 s.
  timeout 120 chromium --headless --no-sandbox --use-gl=angle --use-angle=swiftshader --enable-unsafe-swiftshader \
    --window-size=1280,800 --virtual-time-budget=15000 --screenshot="$shot" "$url?t=4" >/dev/null 2>&1 || true
  [[ -s "$shot" ]] && echo "screenshot of the page at t = 4 s: $shot"
  echo "open $url in a browser to replay the run"
else
  echo "open $url in a browser to replay the run"
fi
exit "$status"
