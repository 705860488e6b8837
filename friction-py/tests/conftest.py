"""Fixtures shared by the tests."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """The `friction` command line: $FRICTION_CLI (CI passes the debug build
    `cargo test` made), else built in release (a no-op when built)."""
    if os.environ.get("FRICTION_CLI"):
        return pathlib.Path(os.environ["FRICTION_CLI"]).resolve()
    subprocess.run(
        ["cargo", "build", "--quiet", "--release", "-p", "friction-host", "--bin", "friction"],
        cwd=ROOT, check=True,
    )
    return ROOT / "target" / "release" / "friction"
