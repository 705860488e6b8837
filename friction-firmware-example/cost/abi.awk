# The servo tick through the C ABI against the same tick called from Rust
# (issue 17: within 10 %), from the M4F `cost-detail` lines. POSIX awk.

function val(key,    i) {
    for (i = 6; i <= NF; i++)
        if (index($i, key "=") == 1) return substr($i, length(key) + 2)
    return ""
}

$1 == "cost-detail" && $3 == "f32" && $4 == "cortex-m4f" && $5 == "fixed" {
    if ($2 == "servo-lugre") rust = val("avg")
    if ($2 == "servo-lugre-c-abi") c = val("avg")
}
END {
    if (rust == "" || c == "") {
        print "FAIL    issue  c-abi servo-lugre rows missing (Rust " rust ", C " c ")"
        exit 1
    }
    ratio = c / rust
    verdict = ratio <= 1.10 ? "ok" : "FAIL"
    printf "%-7s issue  avg   servo-lugre-c-abi f32 cortex-m4f fixed %s vs Rust %s: %.3fx <= 1.10x\n", \
        verdict, c, rust, ratio
    exit verdict == "ok" ? 0 : 1
}
