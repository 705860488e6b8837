# The cost table in Markdown from the benchmark's `cost-detail` lines and
# flash.awk's `flash` lines, one pair of files per core (cortex-m4f first).
# POSIX awk.

function val(key,    i) {
    for (i = 6; i <= NF; i++)
        if (index($i, key "=") == 1) return substr($i, length(key) + 2)
    return ""
}

$1 == "flash" {
    core = FILENAME
    sub(/^.*\//, "", core)
    sub(/\.flash$/, "", core)
    flash[core, "step_" $2] = $3 " / " $4
    next
}
$1 == "cost-detail" {
    key = $2 " " $3 " " $5
    if (!(key in seen)) {
        seen[key] = 1
        order[++n] = key
    }
    core = $4
    avg[key, core] = val("avg")
    worst[key, core] = val("worst")
    ratio[key, core] = val("ratio")
    ram[key] = val("model-bytes") " + " val("state-bytes")
    stack[key, core] = val("stack-bytes")
    fl[key, core] = flash[core, val("fn")]
}
END {
    print "| row | scalar | form | M4F avg | M4F worst | M0 avg | M0 worst | flash M4F | flash M0 | RAM model + state | stack M4F / M0 |"
    print "|---|---|---|---|---|---|---|---|---|---|---|"
    for (i = 1; i <= n; i++) {
        k = order[i]
        split(k, p, " ")
        a = "cortex-m4f"
        b = "cortex-m0"
        printf "| %s | %s | %s | %s | %s (%sx) | %s | %s (%sx) | %s | %s | %s | %s / %s |\n", \
            p[1], p[2], p[3], avg[k, a], worst[k, a], ratio[k, a], avg[k, b], worst[k, b], ratio[k, b], \
            fl[k, a], fl[k, b], ram[k], stack[k, a], stack[k, b]
    }
}
