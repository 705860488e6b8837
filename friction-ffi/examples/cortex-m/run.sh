#!/usr/bin/env bash
# The C example for Cortex-M4F: builds friction-ffi as a staticlib for
# thumbv7em-none-eabihf (profile `firmware`: fat LTO, one codegen unit), compiles main.c + startup.c with arm-none-eabi-gcc
# (main.c: -std=c99 -pedantic -Werror), links, and runs it under QEMU (mps2-an386,
# -icount shift=0). Exit code: the program's (0 when the compensated loop
# meets its bound). Output (semihosting writes to stderr; sent to stdout): the log, including the tick's `cost-detail`
# line. QEMU_TIMEOUT (s, default 120) bounds the run.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ffi="$here/../.."
tdir="${CARGO_TARGET_DIR:-$ffi/../target}"
out="$tdir/ffi-cortex-m"
mkdir -p "$out"

(cd "$ffi" && cargo rustc -p friction-ffi --profile firmware --target thumbv7em-none-eabihf \
  --crate-type staticlib --quiet)
flags=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O2
  -std=c99 -Wall -Wextra -Werror -pedantic -ffreestanding -I"$ffi/include")
arm-none-eabi-gcc "${flags[@]}" -c "$here/main.c" -o "$out/main.o"
# the board glue casts the stack top to a vector: GNU C, not ISO
glue=()
for f in "${flags[@]}"; do [ "$f" = -pedantic ] || [ "$f" = -std=c99 ] || glue+=("$f"); done
arm-none-eabi-gcc "${glue[@]}" -std=gnu99 -c "$here/startup.c" -o "$out/startup.o"
arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
  -nostdlib -T "$here/link.ld" -Wl,--gc-sections -Wl,--no-warn-execstack \
  "$out/main.o" "$out/startup.o" "$tdir/thumbv7em-none-eabihf/firmware/libfriction_ffi.a" -lgcc \
  -o "$out/servo.elf"
timeout "${QEMU_TIMEOUT:-120}" qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 -kernel "$out/servo.elf" 2>&1
