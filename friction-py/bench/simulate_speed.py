"""Speed of `Model.simulate` against the core's own loop (issue 17: within
1.5x on 1e6 samples). A benchmark, not a test: run it on a quiet machine.

    python friction-py/bench/simulate_speed.py

It times `friction.load("params/canudas1995.toml").simulate(t, v)` on 1e6
samples (median of 7) and runs `cargo run --release -p friction-host
--example core_loop`, the LuGre f64 step in a plain Rust loop over the same
signal, and prints both and their ratio.
"""

import pathlib
import re
import subprocess
import time

import numpy as np

import friction

ROOT = pathlib.Path(__file__).resolve().parents[2]
N = 1_000_000


def main() -> None:
    model = friction.load(ROOT / "params" / "canudas1995.toml")
    h = 1e-4
    t = np.arange(N) * h
    v = 2e-3 * np.sin(2 * np.pi * 5 * t)
    runs = []
    for _ in range(7):
        start = time.perf_counter()
        model.simulate(t, v)
        runs.append((time.perf_counter() - start) * 1e9 / N)
    py = sorted(runs)[3]
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "-p", "friction-host", "--example", "core_loop", str(N)],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    core = float(re.search(r"core loop: ([0-9.]+) ns/sample", out).group(1))
    print(f"Model.simulate: {py:.2f} ns/sample (median of 7, {N} samples)")
    print(out.strip())
    print(f"ratio: {py / core:.2f}x (issue 17: within 1.5x)")


if __name__ == "__main__":
    main()
