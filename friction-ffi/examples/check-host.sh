#!/usr/bin/env bash
# The C example on the host against the command line: builds the
# staticlib, compiles examples/simulate.c with gcc -std=c99 -pedantic
# -Werror, runs it and `friction simulate` on the same velocity signal
# (the canudas1995 LuGre set), and fails unless every force agrees to 1e-12 N.
set -euo pipefail
cd "$(dirname "$0")/.."
root=..
tdir="${CARGO_TARGET_DIR:-$root/target}"
out="$tdir/ffi-check"
mkdir -p "$out"

# PROFILE (default release) of the staticlib; FRICTION_CLI: a `friction`
# binary to compare with (CI passes the one `cargo test` built), else it is
# built in PROFILE. Floating-point results are the same in every profile.
profile="${PROFILE:-release}"
dir=$([ "$profile" = dev ] && echo debug || echo "$profile")
cargo build --profile "$profile" -p friction-ffi --quiet
cli="${FRICTION_CLI:-}"
if [ -z "$cli" ]; then
  cargo build --profile "$profile" -p friction-host --bin friction --quiet
  cli="$tdir/$dir/friction"
fi
gcc -std=c99 -Wall -Wextra -Werror -pedantic -O2 -Iinclude examples/simulate.c \
  "$tdir/$dir/libfriction_ffi.a" -lpthread -ldl -lm -o "$out/simulate"

# 20,000 rows at 10 kHz: a 5 Hz sine of 2 mm/s plus 0.3 mm/s of drift,
# through zero 200 times (stick, reversals, sliding)
awk 'BEGIN { print "t,v"; pi = 3.141592653589793;
  for (k = 0; k < 20000; k++) { t = k * 1e-4;
    printf "%.17g,%.17g\n", t, 2e-3 * sin(2 * pi * 5 * t) + 3e-4 * sin(2 * pi * 0.7 * t) } }' \
  >"$out/input.csv"

"$out/simulate" <"$out/input.csv" >"$out/c.csv"
"$cli" simulate --params "$root/params/canudas1995.toml" \
  --input "$out/input.csv" --output "$out/cli.csv" >/dev/null

# column f of each, row by row
awk -F, 'NR == FNR { if (FNR == 1) { for (i = 1; i <= NF; i++) if ($i == "f") c = i; next }
                     f[FNR] = $c; n = FNR; next }
         FNR == 1 { for (i = 1; i <= NF; i++) if ($i == "f") d = i; next }
         { e = $d - f[FNR]; if (e < 0) e = -e; if (e > worst) worst = e; rows++ }
         END { if (rows != n - 1 || rows < 20000) { print "row count differs: " rows " vs " n - 1; exit 1 }
               printf "C ABI vs friction simulate: %d rows, largest force difference %.3g N\n", rows, worst;
               exit (worst <= 1e-12 ? 0 : 1) }' "$out/cli.csv" "$out/c.csv"
