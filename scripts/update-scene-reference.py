#!/usr/bin/env python3
"""Pastes `clothsim help scene --markdown` into docs/scene-reference.md, block by block
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
readme = open(DOC).read()
missing = set(blocks) - {m.group(1) for m in pattern.finditer(readme)}
if missing:
    sys.exit(DOC + " lacks the blocks " + ", ".join(sorted(missing)) + "; add their markers")
open(DOC, "w").write(pattern.sub(lambda m: blocks[m.group(1)], readme))
