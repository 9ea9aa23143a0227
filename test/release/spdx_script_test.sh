#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# test_release_spdx_script: scripts/spdx-headers.sh on sample files in a temporary directory (not a git checkout,
# so the script lists files with find). Checks each comment syntax, the shebang rule, the skipped paths (build
# trees, node_modules, Markdown, HTML), --check's list and exit status, and that a second run changes nothing.
set -euo pipefail
script="$1"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir -p "$tmp/src" "$tmp/build/gen" "$tmp/x/node_modules/three" "$tmp/.ci" "$tmp/docs"
printf '#pragma once\nint f();\n' >"$tmp/src/a.h"
printf 'int f() { return 1; }\n' >"$tmp/src/a.cpp"
printf '"use strict";\nconst x = 1;\n' >"$tmp/src/page.js"
printf '#!/usr/bin/env python3\n"""doc"""\nprint(1)\n' >"$tmp/src/tool.py"
printf '#!/usr/bin/env bash\necho hi\n' >"$tmp/src/run.sh"
chmod +x "$tmp/src/run.sh"
printf 'add_library(a a.cpp)\n' >"$tmp/src/CMakeLists.txt"
printf 'set(X 1)\n' >"$tmp/src/Find.cmake"
printf '#!/usr/bin/env bash\nset -e\n' >"$tmp/.ci/run"
printf '// SPDX-License-Identifier: MIT\n// Copyright (c) 2026 The Scree authors\nint g();\n' >"$tmp/src/done.h"
printf 'int generated();\n' >"$tmp/build/gen/gen.h"
printf 'export const T = 1;\n' >"$tmp/x/node_modules/three/three.js"
printf '# Title\n' >"$tmp/docs/page.md"
printf '<!DOCTYPE html>\n' >"$tmp/src/viewer.html"

# --check lists the 8 files without a header and fails.
if out=$(bash "$script" --check --root "$tmp" 2>&1); then fail "--check passed on files without headers"; fi
echo "$out"
for f in src/a.h src/a.cpp src/page.js src/tool.py src/run.sh src/CMakeLists.txt src/Find.cmake .ci/run; do
  grep -qx "  $f" <<<"$out" || fail "--check does not list $f"
done
[[ $(grep -c '^  ' <<<"$out") == 8 ]] || fail "--check lists other files too"

bash "$script" --root "$tmp"
c='// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors'
h='# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors'
[[ "$(cat "$tmp/src/a.h")" == "$c"$'\n#pragma once\nint f();' ]] || fail "a.h: $(cat "$tmp/src/a.h")"
[[ "$(cat "$tmp/src/page.js")" == "$c"$'\n"use strict";\nconst x = 1;' ]] || fail "page.js"
[[ "$(cat "$tmp/src/tool.py")" == $'#!/usr/bin/env python3\n'"$h"$'\n"""doc"""\nprint(1)' ]] || fail "tool.py: $(cat "$tmp/src/tool.py")"
[[ "$(cat "$tmp/src/run.sh")" == $'#!/usr/bin/env bash\n'"$h"$'\necho hi' ]] || fail "run.sh"
[[ -x "$tmp/src/run.sh" ]] || fail "run.sh lost its executable bit"
[[ "$(cat "$tmp/src/CMakeLists.txt")" == "$h"$'\nadd_library(a a.cpp)' ]] || fail "CMakeLists.txt"
[[ "$(cat "$tmp/.ci/run")" == $'#!/usr/bin/env bash\n'"$h"$'\nset -e' ]] || fail ".ci/run"
[[ "$(cat "$tmp/src/done.h")" == "$c"$'\nint g();' ]] || fail "done.h was changed"
[[ "$(cat "$tmp/build/gen/gen.h")" == 'int generated();' ]] || fail "a build tree file was changed"
[[ "$(cat "$tmp/x/node_modules/three/three.js")" == 'export const T = 1;' ]] || fail "node_modules was changed"
[[ "$(cat "$tmp/docs/page.md")" == '# Title' ]] || fail "Markdown was changed"
[[ "$(cat "$tmp/src/viewer.html")" == '<!DOCTYPE html>' ]] || fail "the HTML template was changed"

# Idempotent: a second run changes nothing, and --check passes.
before=$(cd "$tmp" && find . -type f -exec md5sum {} + | sort)
bash "$script" --root "$tmp" | grep -q 'added the header to 0 file' || fail "second run added headers again"
after=$(cd "$tmp" && find . -type f -exec md5sum {} + | sort)
[[ "$before" == "$after" ]] || fail "second run changed files"
bash "$script" --check --root "$tmp" || fail "--check fails after the script ran"
echo "PASS"
