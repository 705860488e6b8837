#!/usr/bin/env python3
"""Counts a QEMU execution trace by function and source line (profile.sh).

Usage: profile.py NM ELF TRACE STEPS [LINES [WITHIN]]

NM is llvm-nm, ELF the profile binary, TRACE the log of
`qemu-system-arm -singlestep -d exec,nochain` (one line per executed
instruction), STEPS the comma-separated number of steps each case runs
(the counts are divided by it), LINES how many source lines to print per
case (default 12; needs arm-none-eabi-addr2line, skipped without it), and
WITHIN the part of a source path a line is attributed to when arithmetic is
inlined into it (default `src/models/`: the model's own line).

Only the instructions between an entry into `mark_begin` and the next
entry into `mark_end` are counted; each such span is one case.
"""

import bisect
import collections
import re
import shutil
import subprocess
import sys


def symbols(nm, elf):
    """(start, size, name) of every function, sorted by start."""
    out = subprocess.run(
        [nm, "-C", "-S", "--defined-only", elf], capture_output=True, text=True, check=True
    ).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2].lower() in ("t", "w"):
            name = re.sub(r"::h[0-9a-f]{16}$", "", parts[3])
            # what llvm-nm -C leaves of the legacy mangling
            for code, text in (("$LT$", "<"), ("$GT$", ">"), ("$u20$", " "), ("$C$", ","), ("..", "::")):
                name = name.replace(code, text)
            name = name.lstrip("_")
            syms.append((int(parts[0], 16) & ~1, int(parts[1], 16), name))
    syms.sort()
    return syms


def main():
    nm, elf, trace, steps = sys.argv[1:5]
    lines = int(sys.argv[5]) if len(sys.argv) > 5 else 12
    within = sys.argv[6] if len(sys.argv) > 6 else "src/models/"
    steps = [float(s) for s in steps.split(",")]
    syms = symbols(nm, elf)
    starts = [s[0] for s in syms]

    def function(addr):
        i = bisect.bisect_right(starts, addr) - 1
        if i >= 0 and addr < syms[i][0] + syms[i][1]:
            return syms[i][2]
        return "?"

    def entry(addr):
        i = bisect.bisect_right(starts, addr) - 1
        return syms[i][2] if i >= 0 and syms[i][0] == addr else None

    begin = next(s[0] for s in syms if s[2].endswith("mark_begin"))
    end = next(s[0] for s in syms if s[2].endswith("mark_end"))
    pc = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")
    cases, counts = [], None
    with open(trace) as log:
        for line in log:
            m = pc.search(line)
            if not m:
                continue
            addr = int(m.group(1), 16)
            if addr == begin:
                counts = collections.Counter()
            elif addr == end and counts is not None:
                cases.append(counts)
                counts = None
            elif counts is not None:
                counts[addr] += 1
    addr2line = shutil.which("arm-none-eabi-addr2line")
    for n, counts in enumerate(cases):
        per = steps[n] if n < len(steps) else 1.0
        print(f"=== case {n}: {sum(counts.values()) / per:.1f} instructions a step")
        by_fn, calls = collections.Counter(), collections.Counter()
        for addr, k in counts.items():
            by_fn[function(addr)] += k
            name = entry(addr)
            if name:
                calls[name] += k
        for name, k in by_fn.most_common(10):
            print(f"  {k / per:8.1f}  calls {calls[name] / per:5.1f}  {name[:100]}")
        if not (addr2line and lines):
            continue
        addrs = sorted(counts)
        by_line = collections.Counter()
        for addr in addrs:
            # the inlined frames, innermost first: the line is the first
            # that matches `within` (a model's own source, not the
            # arithmetic inlined into it), else the innermost
            frames = subprocess.run(
                [addr2line, "-i", "-e", elf, hex(addr)],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.split()
            frames = [re.sub(r".*/(friction-core|friction-firmware-example|library)/", r"\1/", f) for f in frames]
            loc = next((f for f in frames if within in f), frames[0] if frames else "?")
            by_line[loc] += counts[addr]
        for loc, k in by_line.most_common(lines):
            print(f"    {k / per:8.1f}  {loc}")


if __name__ == "__main__":
    main()
