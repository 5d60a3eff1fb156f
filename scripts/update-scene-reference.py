#!/usr/bin/env python3
"""Pastes `clothsim help scene --markdown` into docs/scene-reference.md (and
docs/input-check.md), block by block
between the <!-- scene-reference:begin/end SECTION --> markers (the check
is tests/cli_scene_reference.sh). Usage, from the repository root:
update-scene-reference.py CLOTHSIM"""
import re, subprocess, sys

DOC = "docs/scene-reference.md"

gen = subprocess.run([sys.argv[1], "help", "scene", "--markdown"], check=True,
                     capture_output=True, text=True).stdout
pattern = re.compile(r"^<!-- scene-reference:begin ([a-z_]+) -->$.*?^<!-- scene-reference:end \1 -->$",
                     re.S | re.M)
blocks = {m.group(1): m.group(0) for m in pattern.finditer(gen)}
# docs/scene-reference.md holds every section's block but the `check`
# section's, which docs/input-check.md holds (the command it belongs to is
# documented there).
files = [DOC, "docs/input-check.md"]
texts = {f: open(f).read() for f in files}
have = {m.group(1) for t in texts.values() for m in pattern.finditer(t)}
missing = set(blocks) - have
if missing:
    sys.exit(" and ".join(files) + " lack the blocks " + ", ".join(sorted(missing)) +
             "; add their markers")
for f, t in texts.items():
    open(f, "w").write(pattern.sub(lambda m: blocks[m.group(1)], t))
