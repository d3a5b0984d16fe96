"""Fixtures of the robocal Python suite: the repository, the CLI to compare against, the data."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import robocal

ROOT = Path(os.environ.get("ROBOCAL_ROOT", Path(__file__).resolve().parents[3]))


def example(name: str) -> str:
    """The path of examples/NAME."""
    return str(ROOT / "examples" / name)


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """Runs the robocal CLI (ROBOCAL_BIN, default target/release/robocal); returns stdout."""
    exe = Path(os.environ.get("ROBOCAL_BIN", ROOT / "target" / "release" / "robocal"))
    if not exe.is_file():
        pytest.fail(f"the robocal CLI is not at {exe}: build it (cargo build --release) or set ROBOCAL_BIN")

    def run(*args: str) -> str:
        p = subprocess.run([str(exe), *args], capture_output=True, text=True)
        assert p.returncode == 0, f"robocal {' '.join(args)} exited {p.returncode}:\n{p.stderr}"
        return p.stdout

    run.exe = exe
    return run


@pytest.fixture(scope="session")
def real_data() -> Path:
    """The real data sets (../shared/data beside the checkout, or ROBOCAL_REAL_DATA)."""
    d = Path(os.environ.get("ROBOCAL_REAL_DATA", ROOT.parent / "shared" / "data"))
    if not (d / "jacobi_ur5_grid.csv").is_file():
        pytest.skip(f"real data not found at {d} (the folder is optional)")
    return d


@pytest.fixture(scope="session")
def ur5() -> robocal.Robot:
    return robocal.Robot.from_file(example("ur5.toml"))


def load_csv(path):
    """A measurement CSV as (q, xyz, set labels); q and xyz as float64 arrays."""
    a = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    names = a.dtype.names
    qcols = [n for n in names if n.startswith("q") and n[1:].isdigit()]
    q = np.column_stack([a[n].astype(float) for n in qcols])
    xyz = np.column_stack([a[n].astype(float) for n in ("x", "y", "z")])
    sets = a["set"] if "set" in names else np.array([""] * len(a))
    return q, xyz, sets


def read_json(path) -> dict:
    with open(path) as f:
        return json.load(f)
