# Flash per cost row: the bytes of a row's `step_<row>` function and of every
# function it reaches through direct branches (bl, b, b.w, blx: libm, the
# soft-float routines of compiler-builtins), each counted once. Constants a
# function loads from .rodata are not counted (literal pools inside a
# function are). POSIX awk.
#
# Input, in this order: `llvm-nm -S --defined-only ELF` (address size type
# name), a line `--`, then `llvm-objdump -d --no-show-raw-insn ELF`.
# Output: `flash ROW SELF CLOSURE` for every `step_<row>` function.

BEGIN { part = 1 }
part == 1 && $0 == "--" { part = 2; next }
part == 1 {
    if (NF >= 4 && ($3 == "t" || $3 == "T")) {
        size[$4] = strtonum_hex($2)
        if ($4 ~ /[0-9]step_[a-z0-9_]+[0-9]+h[0-9a-f]+E$/ && $4 !~ /step_none/) roots[$4] = 1
    }
    next
}
# a function starts: "000108f0 <_ZN4cost...E>:"
/^[0-9a-f]+ <[^>]+>:$/ {
    f = $2
    sub(/^</, "", f)
    sub(/>:$/, "", f)
    next
}
# a direct branch to another function's start: "... bl 0x12e62 <name> @ ..."
f != "" && /\t(bl|blx|b|b\.w|b\.n)\t/ {
    if (match($0, /<[^>+]+>/)) {
        t = substr($0, RSTART + 1, RLENGTH - 2)
        if (t != f && !((f, t) in seen)) {
            seen[f, t] = 1
            calls[f] = calls[f] " " t
        }
    }
}
END {
    for (r in roots) {
        split("", done)
        n = 1
        queue[1] = r
        done[r] = 1
        total = 0
        for (i = 1; i <= n; i++) {
            g = queue[i]
            total += size[g]
            m = split(calls[g], cs, " ")
            for (j = 1; j <= m; j++) {
                if (!(cs[j] in done) && (cs[j] in size)) {
                    done[cs[j]] = 1
                    queue[++n] = cs[j]
                }
            }
        }
        name = r
        sub(/^.*[0-9]step_/, "", name)
        sub(/17h[0-9a-f]+E$/, "", name)
        print "flash", name, size[r], total
    }
}

function strtonum_hex(s,    i, c, v) {
    v = 0
    s = tolower(s)
    for (i = 1; i <= length(s); i++) {
        c = index("0123456789abcdef", substr(s, i, 1)) - 1
        v = v * 16 + c
    }
    return v
}
