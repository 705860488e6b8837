#!/usr/bin/env bash
# The Cortex-M cost table: builds the cost benchmark (src/bin/cost.rs) for
# thumbv7em-none-eabihf and thumbv6m-none-eabi, runs each under QEMU with
# -icount shift=0 (mps2-an386, a Cortex-M4F; mps2-an385, a Cortex-M3 that
# runs the Thumb-1 build), sizes every row's step in the ELF, prints the
# `cost MODEL SCALAR CORE INSTRUCTIONS_PER_STEP` lines and the table, and
# checks budgets.txt (exit 1 when a row exceeds its budget). It also runs the
# C ABI's servo tick (friction-ffi/examples/cortex-m: needs arm-none-eabi-gcc)
# and checks it within 10 % of the Rust tick.
#
# Needs qemu-system-arm, the two thumb targets and the rustup component
# llvm-tools (llvm-nm, llvm-objdump). QEMU_TIMEOUT (s, default 300) bounds
# each run. Raw output goes to target/cost/ (under CARGO_TARGET_DIR if set).
set -euo pipefail
cd "$(dirname "$0")"

# shellcheck source=cost/setup.sh
source cost/setup.sh llvm-nm llvm-objdump
out="$tdir/cost"
mkdir -p "$out"

# target, QEMU machine (and cpu), core label
rows=(
  "thumbv7em-none-eabihf|-machine mps2-an386 -cpu cortex-m4|cortex-m4f"
  "thumbv6m-none-eabi|-machine mps2-an385|cortex-m0"
)
for r in "${rows[@]}"; do
  IFS='|' read -r target machine core <<<"$r"
  cargo build --release --bin cost --target "$target" --quiet
  elf="$tdir/$target/release/cost"
  # shellcheck disable=SC2086 # $machine is two options
  if ! timeout "$limit" qemu-system-arm $machine -nographic \
    -semihosting-config enable=on,target=native -icount shift=0 \
    -kernel "$elf" >"$out/$core.txt"; then
    cat "$out/$core.txt" >&2
    echo "cost.sh: the $core run failed or timed out (${limit}s)" >&2
    exit 1
  fi
  grep -q '^cost-done$' "$out/$core.txt" || {
    echo "cost.sh: the $core run stopped early" >&2
    exit 1
  }
  { "$tools/llvm-nm" -S --defined-only "$elf"; echo --; "$tools/llvm-objdump" -d --no-show-raw-insn "$elf"; } |
    awk -f cost/flash.awk >"$out/$core.flash"
done

# the compensated servo tick through the C ABI (friction-ffi/examples/cortex-m,
# C compiled with arm-none-eabi-gcc against the staticlib): an M4F row
if ! QEMU_TIMEOUT="$limit" bash ../friction-ffi/examples/cortex-m/run.sh >"$out/c-abi.txt"; then
  cat "$out/c-abi.txt" >&2
  echo "cost.sh: the C ABI run failed or timed out (${limit}s)" >&2
  exit 1
fi
grep -q '^c-abi-done$' "$out/c-abi.txt" || {
  echo "cost.sh: the C ABI run stopped early" >&2
  exit 1
}
grep -E '^cost(-worst|-detail)? ' "$out/c-abi.txt" >>"$out/cortex-m4f.txt"

# the lines of the issue's format, then the table
cat "$out"/cortex-m4f.txt "$out"/cortex-m0.txt | grep -E '^cost(-worst)? '
echo
awk -f cost/table.awk "$out"/cortex-m4f.flash "$out"/cortex-m4f.txt "$out"/cortex-m0.flash "$out"/cortex-m0.txt
echo
status=0
awk -f cost/check.awk budgets.txt "$out"/cortex-m4f.txt "$out"/cortex-m0.txt || status=1
# issue 17: the tick through the C ABI within 10 % of the Rust call
awk -f cost/abi.awk "$out"/cortex-m4f.txt || status=1
exit "$status"
