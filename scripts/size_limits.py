#!/usr/bin/env python3
"""Files over 600 lines and functions over 100 lines (the style limits).

Usage: python3 scripts/size_limits.py [DIR ...]   (default: framework/src)

A function runs from its `fn` line to the brace that closes it (strings and
comments stripped before counting braces). Exits 1 when anything is over.
"""
import pathlib
import re
import sys

over = 0
for root in sys.argv[1:] or ["framework/src"]:
    for f in sorted(pathlib.Path(root).rglob("*.rs")):
        lines = f.read_text().splitlines()
        if len(lines) > 600:
            print(f"{f}: {len(lines)} lines (file)")
            over += 1
        i = 0
        while i < len(lines):
            head = lines[i]
            if re.match(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(unsafe\s+)?fn\s+\w+", head) and not head.strip().endswith(";"):
                depth, started, j = 0, False, i
                while j < len(lines):
                    code = re.sub(r'"(\\.|[^"\\])*"', '""', lines[j]).split("//")[0]
                    depth += code.count("{") - code.count("}")
                    started |= "{" in code
                    if started and depth <= 0:
                        break
                    j += 1
                if j - i + 1 > 100:
                    print(f"{f}:{i + 1}: {j - i + 1} lines: {head.strip()[:70]}")
                    over += 1
            i += 1
print(f"{over} over the limits")
sys.exit(1 if over else 0)
