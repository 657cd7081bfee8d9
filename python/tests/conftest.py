"""Shared fixtures: the fvp program (FVP_EXE) and a capture set it writes once per run."""
import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def fvp_exe():
    exe = os.environ.get("FVP_EXE")
    if not exe or not os.path.exists(exe):
        pytest.fail("FVP_EXE must name the fvp program (CTest sets it)")
    return exe


@pytest.fixture(scope="session")
def capture_set(fvp_exe, tmp_path_factory):
    """Seed 2's cluster from 6 views over a 90 degree arc, with ground truth."""
    out = tmp_path_factory.mktemp("captures") / "seed2"
    subprocess.run([fvp_exe, "capture", "--seed", "2", "--views", "6", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    return out


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "heavy: minutes long; run by the python.pytest_heavy CTest (label heavy)")
