#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# The Debian package test: builds libscree-dev_<version>_<arch>.deb from a built tree with CPack, unpacks it into
# a fresh root (dpkg -x: the system's dpkg database and /usr are not touched), and checks that
#   1. its control fields are right: Package libscree-dev, Version = the CMake package version
#      (ScreeConfigVersion.cmake) = getVersionString() of the packaged library (step 5), Depends names the -dev
#      packages of cmake/ScreePackaging.cmake;
#   2. it holds the static libraries, the headers (scree/scree.h, the generated scree/version_number.h), the
#      CMake package files, the scree program and the copyright/licence files, all under /usr;
#   3. its dependencies resolve: `apt-get install --simulate ./libscree-dev_*.deb` on this machine, and the
#      same against an EMPTY dpkg status (apt then plans every package a fresh Debian 12 would need, from the
#      apt lists) — both must plan to install libscree-dev, the second every Depends entry too;
#   4. test/consumer configures against the unpacked root only (Scree_DIR must be inside it), builds, and runs
#      (the box rests); no project warning/sanitizer flag leaks into its flags;
#   5. the consumer prints "Scree <version> (" with the package's version, and `scree --version` says the same;
#   6. every file the consumer's compile and link lines name outside the root belongs (dpkg -S) to a package
#      that Depends reaches, or to g++'s closure (Recommends): the Depends list is complete for linking;
#   7. the packaged `scree` runs a scene, records it and writes the replay page, which keeps three.js's
#      @license header (THIRD-PARTY.md).
#
#   bash scripts/package-test.sh            (uses build/, which must be configured and built)
# Environment: SCREE_BUILD_DIR (default build), SCREE_JOBS, SCREE_KEEP_TMP=1 (keep the temporary directory).
# Needs dpkg-dev (dpkg-shlibdeps for CPack) and file (scripts/install-deps.sh installs both).
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$SCREE_ROOT"
build_dir="$(cd "${SCREE_BUILD_DIR:-build}" && pwd)"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/scree-deb.XXXXXX")"
[[ "${SCREE_KEEP_TMP:-0}" == 1 ]] && echo "keeping $tmp" || trap 'rm -rf "$tmp"' EXIT

fail() { echo "package-test: FAIL: $*" >&2; exit 1; }
[[ -f "$build_dir/CPackConfig.cmake" ]] || fail "$build_dir is not configured (no CPackConfig.cmake)"

cmake_version=$(sed -n 's/^set(PACKAGE_VERSION "\([^"]*\)")$/\1/p' "$build_dir/ScreeConfigVersion.cmake")
[[ -n "$cmake_version" ]] || fail "no PACKAGE_VERSION in $build_dir/ScreeConfigVersion.cmake"

step "1. cpack: the .deb"
run cpack --config "$build_dir/CPackConfig.cmake" -B "$tmp/deb" >"$tmp/cpack.log" 2>&1 || { cat "$tmp/cpack.log"; fail "cpack"; }
debs=("$tmp"/deb/libscree-dev_*.deb)
[[ ${#debs[@]} -eq 1 && -f "${debs[0]}" ]] || fail "expected one libscree-dev_*.deb in $tmp/deb"
deb="${debs[0]}"
ls -l "$deb"
dpkg-deb -f "$deb" | sed 's/^/  /'
field() { dpkg-deb -f "$deb" "$1"; }
[[ "$(field Package)" == libscree-dev ]] || fail "Package is '$(field Package)'"
[[ "$(field Version)" == "$cmake_version" ]] || fail "Version '$(field Version)' != CMake package version '$cmake_version'"
[[ "$(basename "$deb")" == "libscree-dev_${cmake_version}_$(dpkg --print-architecture).deb" ]] \
  || fail "file name $(basename "$deb")"
depends="$(field Depends)"
dev_deps=(libeigen3-dev libccd-dev libpng-dev zlib1g-dev)
grep -q '^SCREE_WITH_SUITESPARSE:BOOL=ON$' "$build_dir/CMakeCache.txt" && dev_deps+=(libsuitesparse-dev)
for d in "${dev_deps[@]}"; do
  [[ ", $depends," == *", $d"[\ ,]* ]] || fail "Depends lacks $d: $depends"
done
echo "version $cmake_version; Depends: $depends"

step "2. unpack into a fresh root (dpkg -x) and check the contents"
root="$tmp/root"
run dpkg -x "$deb" "$root"
outside=$(dpkg-deb -c "$deb" | awk '{print $6}' | grep -v -E '^\./(usr/)?$|^\./usr/' || true)
[[ -z "$outside" ]] || fail "files outside /usr: $outside"
for f in usr/lib/libscree_core.a usr/lib/libscree_collide.a usr/lib/libscree_solver.a usr/lib/libscree_model.a \
         usr/lib/libscree_io.a usr/include/scree/scree.h usr/include/scree/version.h \
         usr/include/scree/version_number.h usr/lib/cmake/Scree/ScreeConfig.cmake \
         usr/lib/cmake/Scree/ScreeConfigVersion.cmake usr/lib/cmake/Scree/ScreeTargets.cmake \
         usr/lib/cmake/Scree/FindCCD.cmake usr/bin/scree usr/share/doc/libscree-dev/copyright \
         usr/share/doc/libscree-dev/LICENSE usr/share/doc/libscree-dev/THIRD-PARTY.md; do
  [[ -e "$root/$f" ]] || fail "the package lacks /$f"
done
echo "$(dpkg-deb -c "$deb" | grep -c -v '/$') files, all under /usr; the expected ones present"

step "3. dependencies resolve (apt-get --simulate, here and on an empty dpkg status)"
[[ -n "$(ls /var/lib/apt/lists/*_Packages* 2>/dev/null)" ]] || fail "no apt lists: run apt-get update first"
apt-get install --simulate "$deb" >"$tmp/apt-here.log" 2>&1 || { cat "$tmp/apt-here.log"; fail "apt-get --simulate"; }
grep -qE '^Inst libscree-dev |libscree-dev is already the newest' "$tmp/apt-here.log" \
  || { cat "$tmp/apt-here.log"; fail "apt would not install libscree-dev"; }
echo "this machine: $(grep -c '^Inst ' "$tmp/apt-here.log") package(s) to install"
: >"$tmp/empty-status"
apt-get install --simulate -o Dir::State::status="$tmp/empty-status" "$deb" >"$tmp/apt-fresh.log" 2>&1 \
  || { cat "$tmp/apt-fresh.log"; fail "apt-get --simulate on an empty dpkg status"; }
grep -q '^Inst libscree-dev ' "$tmp/apt-fresh.log" || { cat "$tmp/apt-fresh.log"; fail "fresh: libscree-dev not planned"; }
for d in "${dev_deps[@]}"; do
  grep -q "^Inst $d " "$tmp/apt-fresh.log" || fail "fresh system: apt does not plan $d"
done
echo "empty system: apt plans $(grep -c '^Inst ' "$tmp/apt-fresh.log") packages, libscree-dev and ${dev_deps[*]} among them"

step "4. test/consumer against the unpacked root"
run cmake -S test/consumer -B "$tmp/consumer" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$root/usr" \
  -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON >"$tmp/consumer-configure.log" 2>&1 \
  || { cat "$tmp/consumer-configure.log"; fail "consumer configure"; }
grep 'Scree ' "$tmp/consumer-configure.log" || true
scree_dir=$(sed -n 's/^Scree_DIR:PATH=//p' "$tmp/consumer/CMakeCache.txt")
[[ "$scree_dir" == "$root/usr/lib/cmake/Scree" ]] || fail "the consumer found Scree in '$scree_dir', not in the package"
run cmake --build "$tmp/consumer" -j "$SCREE_JOBS"
if grep -HnE -- '-Wall|-Wextra|-fsanitize|EIGEN_MPL2_ONLY' "$tmp/consumer/CMakeFiles/app.dir/flags.make" \
     "$tmp/consumer/CMakeFiles/app.dir/link.txt"; then
  fail "the package passes project compile/link flags to consumers (above)"
fi
run "$tmp/consumer/app" | tee "$tmp/app.out"

step "5. versions agree"
grep -q "^Scree $cmake_version (" "$tmp/app.out" || fail "the consumer's library says '$(head -1 "$tmp/app.out")', not $cmake_version"
scree_version=$("$root/usr/bin/scree" --version)
echo "scree --version: $scree_version"
[[ "$scree_version" == "Scree $cmake_version ("* ]] || fail "scree --version: $scree_version"
echo "deb Version = ScreeConfigVersion.cmake = getVersionString() = $cmake_version"

step "6. every dependency the consumer's build uses comes from a package Depends (or g++) reaches"
# Package names in the closure: apt-cache depends prints each package at column 0, its dependencies indented.
mapfile -t dep_names < <(echo "$depends" | tr ',' '\n' | sed 's/(.*)//; s/|.*//; s/[[:space:]]//g' | grep -v '^$')
apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks --no-replaces \
  --no-enhances "${dep_names[@]}" g++ 2>/dev/null | grep -v '^ ' | sed 's/:.*//' | sort -u >"$tmp/closure"
echo "closure of Depends + g++: $(wc -l <"$tmp/closure") packages"
paths=$( (cat "$tmp/consumer/CMakeFiles/app.dir/flags.make" "$tmp/consumer/CMakeFiles/app.dir/link.txt") \
  | tr ' ' '\n' | sed -E 's/^-(I|isystem|L)//' | grep '^/' | grep -v "^$tmp" | sort -u)
checked=0
for p in $paths; do
  owners=$(dpkg -S "$p" 2>/dev/null | sed 's/: .*//' | tr ',' '\n' | sed 's/:.*//; s/ //g' || true)
  if [[ -z "$owners" && "$p" == /usr/* ]]; then  # merged /usr: some packages register /lib/... paths
    owners=$(dpkg -S "${p#/usr}" 2>/dev/null | sed 's/: .*//' | tr ',' '\n' | sed 's/:.*//; s/ //g' || true)
  fi
  if [[ -z "$owners" && -e "$p" ]]; then  # an alternatives symlink (/usr/bin/c++): the file it resolves to
    owners=$(dpkg -S "$(readlink -f "$p")" 2>/dev/null | sed 's/: .*//' | tr ',' '\n' | sed 's/:.*//; s/ //g' || true)
  fi
  [[ -n "$owners" ]] || fail "$p (used by the consumer's build) belongs to no Debian package"
  ok=0
  for o in $owners; do grep -qx "$o" "$tmp/closure" && ok=1; done
  [[ $ok == 1 ]] || fail "$p belongs to '$owners', which libscree-dev's Depends ($depends) does not reach"
  printf '  %-60s %s\n' "$p" "$(echo $owners)"
  checked=$((checked + 1))
done
[[ $checked -gt 0 ]] || fail "no dependency paths found in the consumer's build files"

step "7. the packaged scree program: run, record, replay page"
(cd "$tmp" && run "$root/usr/bin/scree" run tower10 --time 0.1 --quiet --record tower10.screerec >/dev/null)
[[ -s "$tmp/tower10.screerec" ]] || fail "scree run --record wrote nothing"
if (cd "$tmp" && "$root/usr/bin/scree" view tower10.screerec -o tower10.html >/dev/null 2>"$tmp/view.err"); then
  grep -q 'SPDX-License-Identifier: MIT' "$tmp/tower10.html" && grep -q 'Three.js Authors' "$tmp/tower10.html" \
    || fail "the replay page lost three.js's @license header"
  [[ -f "$root/usr/share/doc/libscree-dev/three.js-LICENSE" ]] || fail "three.js's LICENSE is not in the package"
  echo "replay page written; it keeps three.js's licence header"
elif grep -q 'replay page' "$tmp/view.err"; then
  echo "this build has no replay page (no npm at configure time): $(cat "$tmp/view.err")"
else
  cat "$tmp/view.err"; fail "scree view"
fi

echo
echo "package-test: PASS ($(basename "$deb"))"
