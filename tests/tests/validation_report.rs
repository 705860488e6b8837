//! The main job end to end: `validate` passes and writes its report and plots.

#[test]
fn validate_passes_and_writes_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let pass = friction_host::validate::run(dir.path()).unwrap();
    let report = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(pass, "validation failed:\n{report}");
    assert!(report.contains("Overall: **pass**"));
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
