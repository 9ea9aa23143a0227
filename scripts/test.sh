#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# Builds Scree and runs its test suites:
#   1. installs missing Debian packages (scripts/install-deps.sh),
#   2. configures build/ in Release with tests (benchmarks and examples are built too, so they keep compiling),
#   3. builds everything with -j$(nproc),
#   4. runs ctest --test-dir build --output-on-failure -j2 and exits with its status.
# Extra arguments go to ctest, e.g. `bash scripts/test.sh -L analytic` or `-R test_unit_math`.
# Environment: SCREE_JOBS (parallel build jobs, default: all cores), SCREE_BUILD_DIR (default: build).
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$SCREE_ROOT"
build_dir="${SCREE_BUILD_DIR:-build}"

step "Checking build dependencies"
bash scripts/install-deps.sh
echo "dependencies: ok"

step "Configuring $build_dir/ (Release, tests on)"
run cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DSCREE_BUILD_TESTS=ON

step "Building (-j$SCREE_JOBS)"
run cmake --build "$build_dir" -j "$SCREE_JOBS"

step "Running the tests"
status=0
run ctest --test-dir "$build_dir" --output-on-failure -j2 "$@" || status=$?
if [[ $status -eq 0 ]]; then echo "tests: all passed"; else echo "tests: FAILED (ctest exit status $status)"; fi
exit "$status"
