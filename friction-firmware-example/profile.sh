#!/usr/bin/env bash
# Where a Cortex-M0 step's instructions go: builds src/bin/profile.rs for
# thumbv6m-none-eabi, runs it under QEMU (mps2-an385) one instruction per
# translation block with an execution log, and counts the instructions
# between its markers by function (with the calls into each) and by source
# line (cost/profile.py). The cases are listed in src/bin/profile.rs:
# Q16.16 LuGre and GMS(4) over a sweep period, the elasto-plastic worst
# steps with at most 1 and 0 zone sub-steps.
#
# Needs qemu-system-arm, the thumbv6m-none-eabi target, the rustup
# component llvm-tools and python3; source lines need
# arm-none-eabi-addr2line. The log (about 350 MB) goes to target/profile/
# and is removed afterwards. Usage: profile.sh [LINES [WITHIN]] (see
# cost/profile.py)
set -euo pipefail
cd "$(dirname "$0")"

# shellcheck source=cost/setup.sh
source cost/setup.sh llvm-nm
nm="$tools/llvm-nm"
out="$tdir/profile"
mkdir -p "$out"
target=thumbv6m-none-eabi
cargo build --release --bin profile --target "$target" --quiet
elf="$tdir/$target/release/profile"
trap 'rm -f "$out/trace.log"' EXIT
timeout "$limit" qemu-system-arm -machine mps2-an385 -nographic \
  -semihosting-config enable=on,target=native -singlestep \
  -d exec,nochain -D "$out/trace.log" -kernel "$elf"
# steps per case: a sweep period, one step, one step, a sweep period, then
# the per-parameter servo's ticks: stress 82, sweep 600, 598 and 599
python3 cost/profile.py "$nm" "$elf" "$out/trace.log" 64,1,1,64,1,1,1,1 "${1:-12}" "${2:-src/models/}"
