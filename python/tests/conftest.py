"""Shared fixtures: the `dualsplit` command line the answers are compared with.

The binary is `$DUALSPLIT_BIN`, else `target/release/dualsplit` of the checkout this folder
is in (`cargo build --release -p dualsplit`). Without it the comparisons skip, except under
`CI`, where they fail.
"""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("DUALSPLIT_BIN") or str(ROOT / "target" / "release" / "dualsplit")
    if not os.path.isfile(path):
        msg = f"no dualsplit binary at {path} (cargo build --release -p dualsplit, or set DUALSPLIT_BIN)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)

    def run(*args, check=True):
        r = subprocess.run([path, "--quiet", *map(str, args)], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"dualsplit {' '.join(map(str, args))} failed:\n{r.stderr}")
        return r

    return run
