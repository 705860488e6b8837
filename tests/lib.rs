//! Acceptance tests live in `tests/`: the core against the host reference solver.
