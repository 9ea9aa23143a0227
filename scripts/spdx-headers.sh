#!/usr/bin/env bash
# Adds the licence header to every project source file that lacks it (Scree is MIT: LICENSE):
#
#   C++ / JavaScript (.h .hpp .cpp .js, and .h.in):       // SPDX-License-Identifier: MIT
#                                                          // Copyright (c) 2026 The Scree authors
#   CMake / Python / shell (CMakeLists.txt .cmake .cmake.in .py .sh, .ci/run):   the same with "# "
#
# The two lines go first, or right after a "#!" line. A file whose first 5 lines already hold
# "SPDX-License-Identifier:" is left alone, so the script is idempotent.
# Skipped: anything under build*/ or node_modules/ (generated, or three.js from npm), and files without a known
# comment syntax (Markdown, images, data, gnuplot, the HTML page template).
#
#   bash scripts/spdx-headers.sh            add the headers (prints each file it changes)
#   bash scripts/spdx-headers.sh --check    change nothing; list the files without a header, exit 1 if any
#   bash scripts/spdx-headers.sh --root DIR ...   work on DIR instead of the repository (the self-test)
#
# The file list is git's (tracked and untracked-but-not-ignored files) inside a git checkout, else `find`.
# The ctest tests test_release_spdx_script (this script on sample files) and test_release_spdx_headers
# (--check on the repository) use it.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
check=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --check) check=1 ;;
    --root) root="$(cd "$2" && pwd)"; shift ;;
    -h|--help) awk 'NR > 1 && !/^#/ {exit} NR > 1 && !/SPDX-License-Identifier|^# Copyright \(c\)/' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "spdx-headers.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done
cd "$root"

readonly SPDX="SPDX-License-Identifier: MIT"
readonly COPYRIGHT="Copyright (c) 2026 The Scree authors"

# The comment prefix of a file, or nothing when the file is not a project source with a known syntax.
comment_of() {
  local f=$1 base=${1##*/}
  case "/$f" in */build*/*|*/node_modules/*|*/.git/*) return 0 ;; esac
  case "$base" in
    *.h|*.hpp|*.cpp|*.js|*.h.in) echo "//" ;;
    CMakeLists.txt|*.cmake|*.cmake.in|*.py|*.sh) echo "#" ;;
    *)
      # Extension-less scripts (.ci/run): a shell shebang.
      if [[ "$base" != *.* ]] && head -1 "$f" 2>/dev/null | grep -qE '^#!.*\b(ba)?sh\b'; then echo "#"; fi ;;
  esac
}

list_files() {
  if git -C "$root" rev-parse --is-inside-work-tree >/dev/null 2>&1 &&
     [[ "$(git -C "$root" rev-parse --show-toplevel)" == "$root" ]]; then
    git ls-files --cached --others --exclude-standard
  else
    find . -type f -not -path './.git/*' | sed 's|^\./||'
  fi
}

missing=()
changed=0
while IFS= read -r f; do
  [[ -f "$f" ]] || continue  # a deleted but still indexed file
  c=$(comment_of "$f")
  [[ -n "$c" ]] || continue
  if head -5 "$f" | grep -q "SPDX-License-Identifier:"; then continue; fi
  if [[ $check == 1 ]]; then
    missing+=("$f")
    continue
  fi
  tmp="$f.spdx-tmp"
  if head -1 "$f" | grep -q '^#!'; then
    { head -1 "$f"; printf '%s %s\n%s %s\n' "$c" "$SPDX" "$c" "$COPYRIGHT"; tail -n +2 "$f"; } >"$tmp"
  else
    { printf '%s %s\n%s %s\n' "$c" "$SPDX" "$c" "$COPYRIGHT"; cat "$f"; } >"$tmp"
  fi
  chmod --reference="$f" "$tmp"
  mv "$tmp" "$f"
  echo "added: $f"
  changed=$((changed + 1))
done < <(list_files | sort)

if [[ $check == 1 ]]; then
  if [[ ${#missing[@]} -gt 0 ]]; then
    echo "spdx-headers.sh: ${#missing[@]} project source file(s) without an SPDX header" \
         "(run bash scripts/spdx-headers.sh):" >&2
    printf '  %s\n' "${missing[@]}" >&2
    exit 1
  fi
  echo "spdx-headers.sh: every project source file has its SPDX header"
  exit 0
fi
echo "spdx-headers.sh: added the header to $changed file(s)"
