# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# shellcheck shell=bash
# Shared helpers for scripts/*.sh (sourced, not run).
# Repository root, whatever the caller's working directory.
SCREE_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export SCREE_ROOT
# Parallel build jobs: SCREE_JOBS, else all cores.
SCREE_JOBS="${SCREE_JOBS:-$(nproc 2>/dev/null || echo 2)}"

# Prints a command, then runs it.
run() {
  printf '+'; printf ' %q' "$@"; printf '\n'
  "$@"
}

step() {
  printf '\n==> %s\n' "$*"
}
