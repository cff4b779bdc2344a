"""The sparse solvers: PARDISO found without searching the environment, and its answers."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from pneumorph.fem import linear

pytest.importorskip("pypardiso")


def test_mkl_runtime_points_at_the_wheels_library_and_restores_the_environment(monkeypatch):
    monkeypatch.delenv("PYPARDISO_MKL_RT", raising=False)
    with linear._mkl_runtime():
        found = os.environ.get("PYPARDISO_MKL_RT")
    assert "PYPARDISO_MKL_RT" not in os.environ
    if found is not None:  # the mkl wheel's layout: <prefix>/lib/libmkl_rt.so.N
        assert Path(found).is_file() and Path(found).parent == Path(sys.prefix) / "lib"


def test_mkl_runtime_keeps_a_path_the_user_set(monkeypatch):
    monkeypatch.setenv("PYPARDISO_MKL_RT", "/somewhere/libmkl_rt.so")
    with linear._mkl_runtime():
        assert os.environ["PYPARDISO_MKL_RT"] == "/somewhere/libmkl_rt.so"
    assert os.environ["PYPARDISO_MKL_RT"] == "/somewhere/libmkl_rt.so"


def test_the_first_pardiso_of_a_process_does_not_search_the_environment():
    """pypardiso makes a solver of its own as it is imported: the import too must see the wheel's library, or it
    searches every file of the environment (0.33 s of CPU, the most of a 4-unit 2D simulate's set-up)."""
    import glob
    import subprocess

    if "PYPARDISO_MKL_RT" in os.environ or not glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")):
        pytest.skip("MKL not installed as the mkl wheel lays it out")
    probe = ("import glob, sys\n"
             "searched = []\n"
             "real = glob.glob\n"
             "def spy(pattern, *args, **kwargs):\n"
             "    if kwargs.get('recursive'):\n"
             "        searched.append(pattern)\n"
             "    return real(pattern, *args, **kwargs)\n"
             "glob.glob = spy\n"
             "from pneumorph.fem.linear import Pardiso\n"
             "Pardiso()\n"
             "assert 'pypardiso' in sys.modules\n"
             "print(searched)\n")
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120, check=True,
                         env={k: v for k, v in os.environ.items() if k != "PYPARDISO_MKL_RT"})
    assert run.stdout.strip() == "[]"


def test_pardiso_solves_a_nonsymmetric_system_to_rounding():
    rng = np.random.default_rng(3)
    A = sp.random(40, 40, density=0.2, random_state=rng) + sp.eye(40) * 5.0
    b = rng.normal(size=40)
    x = linear.Pardiso()(A.tocsr(), b)
    assert np.allclose(A @ x, b, rtol=0, atol=1e-12)


def test_a_system_with_nan_values_gives_nan_and_leaves_the_next_solve_exact():
    """A Newton iterate outside the material's domain assembles NaN: the solution says so, and the next system of
    the same pattern (after a cut-back) is solved exactly, not with an analysis made from the NaN values (a
    composite coupon once failed every cut-back after one such iterate)."""
    rng = np.random.default_rng(4)
    A = (sp.random(40, 40, density=0.2, random_state=rng) + sp.eye(40) * 5.0).tocsr()
    b = rng.normal(size=40)
    solve = linear.Pardiso()
    poisoned = A.copy()
    poisoned.data[::7] = np.nan
    assert np.isnan(solve(poisoned, b)).all()
    x = solve(A, b)
    assert np.allclose(A @ x, b, rtol=0, atol=1e-12)
