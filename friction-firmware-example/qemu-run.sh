#!/usr/bin/env bash
# Runs a firmware ELF under QEMU (mps2-an386, Cortex-M4F) and decodes its
# defmt log. The exit code is the firmware's (semihosting exit), or 124 when
# the time limit kills QEMU.
set -euo pipefail
elf="$1"
limit="${QEMU_TIMEOUT:-120}"
if ! command -v defmt-print >/dev/null; then
  echo "defmt-print not found: cargo install defmt-print" >&2
  exit 127
fi
timeout "$limit" qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf" \
  | defmt-print -e "$elf"
