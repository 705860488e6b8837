# The set-up cost.sh and profile.sh share (sourced, from the firmware
# example's directory): QEMU's time limit `limit` (QEMU_TIMEOUT, s, default
# 300), the target directory `tdir` (CARGO_TARGET_DIR or target), and
# `tools`, the rustup llvm-tools directory, checked for each tool named in
# the arguments.
limit="${QEMU_TIMEOUT:-300}"
tdir="${CARGO_TARGET_DIR:-target}"
host=$(rustc -vV | sed -n 's/^host: //p')
tools="$(rustc --print sysroot)/lib/rustlib/$host/bin"
for tool in "$@"; do
  if [ ! -x "$tools/$tool" ]; then
    echo "$(basename "$0"): $tool not found: rustup component add llvm-tools" >&2
    exit 127
  fi
done
