#!/usr/bin/env bash
# Host comparison of the f64 LuGre step: friction-core (Rust) against the
# hand-written C step, in one run each way:
#   1. callgrind (if valgrind is installed): instructions per step, exact;
#   2. criterion: time per step (noisy on a shared machine; read the ratio).
# Usage: friction-core/benches/c/run.sh [--no-criterion]
set -euo pipefail
cd "$(dirname "$0")"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$(cd ../../.. && pwd)/target}"

if command -v valgrind >/dev/null && command -v callgrind_annotate >/dev/null; then
  cargo build --release -p friction-bench-c --bin callgrind --quiet
  out="$CARGO_TARGET_DIR/lugre-c.callgrind"
  valgrind --tool=callgrind --callgrind-out-file="$out" "$CARGO_TARGET_DIR/release/callgrind" >/dev/null 2>&1
  steps=$("$CARGO_TARGET_DIR/release/callgrind" | sed -n 's/^steps \([0-9]*\).*/\1/p')
  callgrind_annotate --inclusive=yes "$out" 2>/dev/null |
    awk -v steps="$steps" '
      function n(s) { gsub(/,/, "", s); return s + 0 }
      function has(s) { return index($0, s) > 0 }
      # a function shows on several lines (one per source file of inlined
      # code); its inclusive total is the largest
      function most(old) { return n($1) > old ? n($1) : old }
      has("friction_bench_c::rust_step") { r = most(r) }
      # the input checks (friction-core src/model.rs, inlined into rust_step)
      has("src/model.rs:friction_bench_c::rust_step") { chk = most(chk) }
      has("friction_bench_c::c_step") { c = most(c) }
      has("libm::math::exp::exp") { re = most(re) }
      has("libm::math::expm1::expm1") { rm = most(rm) }
      has(":exp@@GLIBC") { ce = most(ce) }
      has(":__expm1") || has(":expm1@@GLIBC") { cm = most(cm) }
      END {
        if (!(r && c)) { print "callgrind: step functions not found"; exit 1 }
        printf "callgrind, instructions per step (%d steps each):\n", steps
        printf "  rust (friction-core LuGre::step)     %7.1f\n", r / steps
        printf "  c (lugre.c, cc -O2, glibc libm)      %7.1f\n", c / steps
        printf "  ratio rust / c                       %7.3f\n", r / c
        printf "  of which exp + expm1: rust (libm crate) %.1f, c (glibc) %.1f\n", (re + rm) / steps, (ce + cm) / steps
        printf "  rust input checks (src/model.rs)     %7.1f\n", chk / steps
        printf "  the rest of the step: rust %.1f, c %.1f\n", (r - re - rm - chk) / steps, (c - ce - cm) / steps
        print c / steps > "'"$out"'.c"
      }'
  # the fixed-step form (build_fixed_step(h), no h checks), in a run of its own
  valgrind --tool=callgrind --callgrind-out-file="$out.fixed" "$CARGO_TARGET_DIR/release/callgrind" fixed >/dev/null 2>&1
  callgrind_annotate --inclusive=yes "$out.fixed" 2>/dev/null |
    awk -v steps="$steps" -v c="$(cat "$out.c")" '
      function n(s) { gsub(/,/, "", s); return s + 0 }
      function most(old) { return n($1) > old ? n($1) : old }
      index($0, "friction_bench_c::rust_fixed_step") > 0 { f = most(f) }
      index($0, "friction_bench_c::c_ie_step") > 0 { ie = most(ie) }
      index($0, "libm::math::exp::exp") > 0 { e = most(e) }
      END {
        if (!f) { print "callgrind: fixed-step function not found"; exit 1 }
        printf "  rust fixed-step (LuGreFixedStep::step) %7.1f (exp %.1f)\n", f / steps, e / steps
        printf "  ratio rust fixed-step / c            %7.3f\n", f / steps / c
        if (ie) {
          printf "  c implicit Euler, one exp (lugre.c)  %7.1f\n", ie / steps
          printf "  ratio rust fixed-step / c implicit Euler %.3f (issue 19: 1.2)\n", f / ie
        }
      }'
else
  echo "callgrind: valgrind not installed, skipped"
fi

if [ "${1:-}" != "--no-criterion" ]; then
  cargo bench -p friction-bench-c --bench lugre_c -- --warm-up-time 1 --measurement-time 3
fi
