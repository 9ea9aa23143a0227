#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
"""test_docs_snippets: every C++ code block the docs show is compiled code, and the compiled snippets run.

The snippets are the files examples/snippets/*.cpp; test/CMakeLists.txt builds each as snippet_<name>. A file's
shown text is either the whole file (without its leading SPDX licence lines) or, when the file has them, each region between a line `// [doc]` and a
line `// [/doc]` (dedented by the region's common indentation), so a page may show a fragment while the file
gives it the declarations around it.

Checks:
  1. every ```cpp / ```c++ block in README.md and docs/**/*.md equals a shown text of some snippet file; a block
     right after a line `<!-- snippet: examples/snippets/NAME.cpp -->` must equal a shown text of that file;
  2. every snippet file is shown somewhere (no stale snippet);
  3. every snippet executable given on the command line exits 0 within 120 s, run in a scratch directory, except
     files marked `// snippet: compile-only` (they are still compiled by the build).

usage: docs_snippets.py SOURCE_DIR RUN_DIR NAME=EXECUTABLE...
"""
import os
import pathlib
import re
import subprocess
import sys

source = pathlib.Path(sys.argv[1])
run_dir = pathlib.Path(sys.argv[2])
executables = dict(arg.split("=", 1) for arg in sys.argv[3:])
errors = []

FENCE = re.compile(r"^```(cpp|c\+\+)\s*$")
MARKER = re.compile(r"^<!--\s*snippet:\s*(\S+)\s*-->\s*$")


def dedent(lines):
    indents = [len(l) - len(l.lstrip(" ")) for l in lines if l.strip()]
    cut = min(indents) if indents else 0
    return "\n".join(l[cut:] if l.strip() else "" for l in lines).strip("\n")


def without_licence_header(text):
    """The file's text without its leading SPDX licence lines (scripts/spdx-headers.sh), which pages omit."""
    lines = text.split("\n")
    while lines and (lines[0].startswith("// SPDX-License-Identifier:") or lines[0].startswith("// Copyright (c)")):
        lines.pop(0)
    return "\n".join(lines)


def shown_texts(path):
    text = without_licence_header(path.read_text())
    lines = text.split("\n")
    regions, current = [], None
    for line in lines:
        if line.strip() == "// [doc]":
            current = []
        elif line.strip() == "// [/doc]":
            if current is None:
                errors.append(f"{path}: '// [/doc]' without '// [doc]'")
            else:
                regions.append(dedent(current))
            current = None
        elif current is not None:
            current.append(line)
    if current is not None:
        errors.append(f"{path}: '// [doc]' without '// [/doc]'")
    return regions if regions else [text.strip("\n")]


snippet_dir = source / "examples" / "snippets"
snippets = {p.relative_to(source).as_posix(): shown_texts(p) for p in sorted(snippet_dir.glob("*.cpp"))}
used = set()

pages = [source / "README.md"] + sorted((source / "docs").rglob("*.md"))
blocks = 0
for page in pages:
    lines = page.read_text().split("\n")
    i = 0
    while i < len(lines):
        if FENCE.match(lines[i]):
            start = i
            j = i + 1
            while j < len(lines) and lines[j].strip() != "```":
                j += 1
            block = "\n".join(lines[i + 1:j]).strip("\n")
            marker = MARKER.match(lines[start - 1]) if start > 0 else None
            where = f"{page.relative_to(source)}:{start + 1}"
            blocks += 1
            if marker:
                name = marker.group(1)
                if name not in snippets:
                    errors.append(f"{where}: names {name}, which is not a snippet file")
                elif block not in snippets[name]:
                    errors.append(f"{where}: the block differs from {name} (copy the file's text into the page)")
                else:
                    used.add(name)
                    print(f"ok  {where}  = {name}")
            else:
                found = [name for name, texts in snippets.items() if block in texts]
                if not found:
                    first = block.split("\n")[0]
                    errors.append(f"{where}: a C++ block ('{first[:60]}...') that no examples/snippets/*.cpp "
                                  "holds: add it to a snippet file between // [doc] and // [/doc]")
                else:
                    used.update(found)
                    print(f"ok  {where}  = {found[0]}")
            i = j + 1
        else:
            i += 1

for name in snippets:
    if name not in used:
        errors.append(f"{name}: not shown by any page (remove it or show it)")

run_dir.mkdir(parents=True, exist_ok=True)
for name in snippets:
    stem = pathlib.Path(name).stem
    text = (source / name).read_text()
    if "// snippet: compile-only" in text:
        print(f"compiled, not run: {name}")
        continue
    exe = executables.get(stem)
    if exe is None:
        errors.append(f"{name}: no executable snippet_{stem} was passed (test/CMakeLists.txt)")
        continue
    try:
        r = subprocess.run([exe], cwd=run_dir, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        errors.append(f"{name}: did not finish in 120 s")
        continue
    out = (r.stdout + r.stderr).strip().replace("\n", "\n      ")
    print(f"ran {name} (exit {r.returncode}):\n      {out}")
    if r.returncode != 0:
        errors.append(f"{name}: exited with {r.returncode}")

print(f"{blocks} C++ blocks in {len(pages)} pages, {len(snippets)} snippet files")
if errors:
    print("\nFAIL:\n  " + "\n  ".join(errors))
    sys.exit(1)
print("PASS")
