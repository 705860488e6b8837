//! The main job end to end: `validate` passes and writes its report and plots.

#[test]
fn validate_passes_and_writes_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let pass = friction_host::validate::run(dir.path()).unwrap();
    let report = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(pass, "validation failed:\n{report}");
    // it opens with the verdict, then the model-by-phenomenon matrix and the accuracy lines
    assert!(
        report
            .lines()
            .nth(2)
            .unwrap()
            .starts_with("**Verdict: pass**"),
        "{report}"
    );
    let matrix = report
        .find("## Phenomena: measured against expected")
        .unwrap();
    let glance = report.find("## Accuracy at a glance").unwrap();
    let details = report
        .find("## Accuracy of the core's discrete step")
        .unwrap();
    assert!(matrix < glance && glance < details);
    for model in [
        "| lugre |",
        "| elasto-plastic |",
        "| dahl |",
        "| reset-integrator |",
        "| bristle |",
    ] {
        assert!(
            report[matrix..glance].contains(model),
            "matrix lacks {model}"
        );
    }
    assert!(report[matrix..glance].contains("yes (expected) ✓"));
    // readable numbers: no long runs of zeros
    assert!(
        !report.contains("00000000"),
        "unreadable number in the report"
    );
    assert!(report.contains("LuGre creeps, elasto-plastic does not"));
    assert!(report.contains("## Servo benchmark") && report.contains("| observer-nodamping |"));
    for name in friction_host::experiments::NAMES {
        assert!(
            report.contains(&format!("| {name} |")),
            "report lacks {name}"
        );
    }
    for plot in [
        "canudas1995-stick-slip/stick-slip.svg",
        "canudas1995-presliding/presliding.svg",
        "accuracy-canudas1995-lugre-0.svg",
        "drift-lugre-vs-elasto-plastic.svg",
        "dahl1968-rate-independence/rate-independence.svg",
    ] {
        let svg = std::fs::read_to_string(dir.path().join(plot)).unwrap();
        assert!(svg.starts_with("<svg") && svg.len() > 1000, "{plot}");
    }
}
