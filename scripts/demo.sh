#!/usr/bin/env bash
# Builds and runs the Scree demo (examples/scree_demo.cpp):
#   1. installs missing Debian packages (scripts/install-deps.sh),
#   2. configures build/ in Release,
#   3. builds the scree_demo target,
#   4. runs build/examples/scree_demo (extra arguments are passed to it).
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

step "Building scree_demo"
run cmake --build "$build_dir" --target scree_demo -j "$SCREE_JOBS"

step "Running the demo"
run "$build_dir/examples/scree_demo" "$@"
