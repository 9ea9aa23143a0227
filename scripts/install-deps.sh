#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# Installs the Debian 12 packages Scree's build needs, only those that are missing.
#
#   bash scripts/install-deps.sh [--with-plot] [--with-bullet] [--check]
#
#   --with-plot  also gnuplot-nox (plots of the benchmark sweeps; the build does not need it)
#   --with-bullet  also libbullet-dev (the optional side-by-side benchmark bench_bullet_granular)
#   --check      only report what is missing; exit 1 if something is
#
# As root: `apt-get update` (only when something is missing) and
# `apt-get install -y --no-install-recommends <missing>` with DEBIAN_FRONTEND=noninteractive.
# As another user: prints the exact command to run as root and exits 1.
# Silent and exit 0 when everything is installed. SCREE_SKIP_DEPS=1 skips the check altogether
# (non-Debian systems with the dependencies installed by other means).
set -euo pipefail

packages=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libccd-dev libpng-dev zlib1g-dev doctest-dev libbenchmark-dev
          libcli11-dev chromium python3-meshio python3-pil
          python3-vtk9  # VTK's own XML readers validate the ParaView export in test_unit_vtk_export
          dpkg-dev file)  # CPack's Debian package: dpkg-shlibdeps (dpkg-dev) on the scree program, which uses file
# npm (three.js for the replay page, fetched from the npm registry at build time): Debian's package only when no
# npm is on the PATH already (a machine with Node.js from elsewhere would conflict with Debian's npm).
command -v npm >/dev/null 2>&1 || packages+=(npm)
check_only=0
for arg in "$@"; do
  case "$arg" in
    --with-plot) packages+=(gnuplot-nox) ;;
    --with-bullet) packages+=(libbullet-dev) ;;
    --check) check_only=1 ;;
    -h|--help) awk 'NR > 1 && !/^#/ {exit} NR > 1 && !/SPDX-License-Identifier|^# Copyright \(c\)/' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "install-deps.sh: unknown option '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

if [[ "${SCREE_SKIP_DEPS:-0}" == 1 ]]; then
  exit 0
fi
if ! command -v dpkg-query >/dev/null 2>&1; then
  echo "install-deps.sh: dpkg-query not found (not a Debian system?); install these by other means:" >&2
  echo "  ${packages[*]}" >&2
  echo "  (set SCREE_SKIP_DEPS=1 to silence this check)" >&2
  exit 1
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [[ "$status" == installed ]] || missing+=("$p")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  exit 0
fi

install_cmd="apt-get install -y --no-install-recommends ${missing[*]}"
if [[ $check_only -eq 1 ]]; then
  echo "install-deps.sh: missing packages: ${missing[*]}" >&2
  exit 1
fi
if [[ $(id -u) -ne 0 ]]; then
  echo "install-deps.sh: missing packages: ${missing[*]}" >&2
  echo "Run as root:" >&2
  echo "  apt-get update && DEBIAN_FRONTEND=noninteractive $install_cmd" >&2
  exit 1
fi

echo "+ apt-get update   (missing: ${missing[*]})"
DEBIAN_FRONTEND=noninteractive apt-get update -q
echo "+ $install_cmd"
DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
