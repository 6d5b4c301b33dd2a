import os
import pathlib

# BLAS threads spin-wait for each other on a loaded machine (tests stalled for minutes in
# exec_blas_async_wait at load 5); the suite's matrices are small, one thread is as fast.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# the suite's workers fill the cores already: re-simulations side by side on threads in each
# worker only add switching (test_resimulate sets the threads where it checks them)
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("HUNTING_THREADS", "1")

import pytest  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


@pytest.fixture(scope="session")
def shared_dir():
    if not SHARED.is_dir():
        pytest.skip(f"shared data directory {SHARED} is absent (it lives beside the project checkout)")
    return SHARED
