//! Issue 32's robustness-map targets with the `[servo]` defaults
//! (`friction robustness`, `docs/guide/servo.md`, "The stiffness law"):
//! on the shipped 7 x 7 grid of friction-level and stiffness errors, the
//! supervised `adaptive` row beats `static` in every cell, and its median
//! is at most half of the θ law's 0.127 mrad.

use friction_host::params::ParamFile;
use friction_host::servo::robustness::{map, Grid, COMPENSATIONS};
use std::path::Path;

#[test]
fn adaptive_beats_static_in_every_cell_and_halves_the_median() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/olsson1998-servo.toml");
    let file = ParamFile::load(&path).unwrap();
    let grid = Grid::new(7).unwrap();
    let m = map(&file, "olsson1998-servo.toml", &grid, &|_, _| {}).unwrap();
    let column = |name: &str| COMPENSATIONS.iter().position(|c| *c == name).unwrap();
    let (stat, adaptive) = (column("static"), column("adaptive"));
    assert_eq!(m.cells.len(), 49);
    for c in &m.cells {
        assert!(
            c.rms[adaptive] < c.rms[stat],
            "levels {} stiffness {}: adaptive {} static {}",
            c.force,
            c.stiffness,
            c.rms[adaptive],
            c.rms[stat]
        );
    }
    let mut errors: Vec<f64> = m.cells.iter().map(|c| c.rms[adaptive]).collect();
    errors.sort_by(f64::total_cmp);
    let median = errors[errors.len() / 2];
    assert!(median <= 0.5 * 0.127, "median {median} mrad");
}
