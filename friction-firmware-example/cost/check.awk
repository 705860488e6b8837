# Checks the benchmark's `cost-detail` lines against budgets.txt (the first
# file). A rule is `METRIC MODEL SCALAR CORE FORM MAX KIND`, METRIC one of
# avg, worst, ratio (worst / avg), FORM `*` for any form, KIND one of
#   issue   the issue's budget: enforced once the row exists, else pending
#   guard   a regression guard (today's figure + 10 %): enforced, and the
#           row must exist
#   report  printed, never enforced (a known miss, with its reason)
# Exits 1 when an enforced rule fails. POSIX awk.

function val(key,    i) {
    for (i = 6; i <= NF; i++)
        if (index($i, key "=") == 1) return substr($i, length(key) + 2)
    return ""
}

FNR == NR {
    sub(/#.*/, "")
    if (NF == 0) next
    if (NF != 7 || ($1 != "avg" && $1 != "worst" && $1 != "ratio") ||
        ($7 != "issue" && $7 != "guard" && $7 != "report")) {
        printf "budgets.txt:%d: not a rule: %s\n", FNR, $0
        bad = 1
        next
    }
    rules[++nr] = $0
    next
}
$1 == "cost-detail" {
    rows[++nrows] = $2 " " $3 " " $4 " " $5
    value[nrows, "avg"] = val("avg")
    value[nrows, "worst"] = val("worst")
    value[nrows, "ratio"] = val("ratio")
}
END {
    fails = 0
    for (i = 1; i <= nr; i++) {
        split(rules[i], r, " ")
        found = 0
        for (j = 1; j <= nrows; j++) {
            split(rows[j], w, " ")
            if (w[1] != r[2] || w[2] != r[3] || w[3] != r[4] || (r[5] != "*" && w[4] != r[5])) continue
            found = 1
            v = value[j, r[1]] + 0
            why = ""
            if (v <= r[6] + 0) verdict = "ok"
            else if (r[7] == "report") { verdict = "over"; why = "reported, not enforced" }
            else { verdict = "FAIL"; fails++; why = "exceeds its " (r[7] == "guard" ? "regression guard" : "budget") }
            printf "%-7s %-6s %-5s %-16s %-5s %-10s %-8s %10s <= %-8s %s\n", \
                verdict, r[7], r[1], w[1], w[2], w[3], w[4], value[j, r[1]], r[6], why
        }
        if (!found) {
            if (r[7] == "guard") { verdict = "FAIL"; fails++; why = "row missing" }
            else { verdict = "pending"; why = "no row yet" }
            printf "%-7s %-6s %-5s %-16s %-5s %-10s %-8s %10s <= %-8s %s\n", \
                verdict, r[7], r[1], r[2], r[3], r[4], r[5], "-", r[6], why
        }
    }
    if (bad) fails++
    if (nrows == 0) { print "cost check: no cost-detail lines"; fails++ }
    if (fails) {
        printf "cost check: %d rule(s) failed\n", fails
        exit 1
    }
    print "cost check: every enforced budget holds"
}
