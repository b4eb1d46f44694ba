"""Shared fixtures: the shipped samples and the scanfit command line.

The comparisons with the command line need its binary: SCANFIT_BIN, else
target/release/scanfit, else target/debug/scanfit of this repository. When
none exists those tests are skipped with a message saying so; with
SCANFIT_REQUIRE_CLI=1 (CI) a missing binary fails them instead.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "examples" / "data"


def cli_binary():
    env = os.environ.get("SCANFIT_BIN")
    if env:
        return Path(env)
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "scanfit"
        if p.exists():
            return p
    return None


@pytest.fixture(scope="session")
def data():
    return DATA


@pytest.fixture(scope="session")
def cli():
    """Runs `scanfit ARGS...` and returns the parsed JSON it printed (--json)."""
    exe = cli_binary()
    if exe is None or not exe.exists():
        msg = (
            "SKIPPED LOUDLY: no scanfit binary (set SCANFIT_BIN or build "
            "target/release/scanfit); the CLI comparisons did not run"
        )
        if os.environ.get("SCANFIT_REQUIRE_CLI") == "1":
            pytest.fail(msg)
        pytest.skip(msg)

    def run(*args):
        out = subprocess.run(
            [str(exe), *map(str, args)], capture_output=True, text=True, check=False
        )
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout) if "--json" in args else out.stdout

    return run
