"""BLAS settings: ``import gaitlib`` leaves the environment alone; :func:`gaitlib.blas.pin`
sets the Makefile's values only where nothing is set; the command line pins them."""

import os
import re
import subprocess
import sys
from pathlib import Path

from gaitlib import blas

ROOT = Path(__file__).resolve().parents[1]


def _env_without_blas() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in blas.SETTINGS}


def test_import_gaitlib_sets_no_environment_variable():
    code = ("import os, gaitlib, gaitlib.cli; "
            "print({k: os.environ.get(k) for k in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', "
            "'MKL_NUM_THREADS', 'OPENBLAS_CORETYPE')})")
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_blas(), capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == ("{'OPENBLAS_NUM_THREADS': None, 'OMP_NUM_THREADS': None, 'MKL_NUM_THREADS': None, "
                           "'OPENBLAS_CORETYPE': None}")


def test_pin_sets_only_what_is_missing():
    env = {"OPENBLAS_NUM_THREADS": "4", "PATH": "/bin"}
    new = blas.pin(env)
    assert env["OPENBLAS_NUM_THREADS"] == "4"  # the user's choice is kept
    assert new == {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_CORETYPE": "Haswell"}
    assert {k: env[k] for k in new} == new and env["PATH"] == "/bin"
    assert blas.pin(env) == {}  # a second call changes nothing


def test_cli_main_pins_before_numpy_is_imported():
    code = ("import os, sys\nfrom gaitlib import cli\nassert 'numpy' not in sys.modules\n"
            "try:\n    cli.main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['OPENBLAS_CORETYPE'])")
    out = subprocess.run([sys.executable, "-c", code], env=_env_without_blas(), capture_output=True, text=True,
                         check=True).stdout
    assert out.strip().splitlines()[-1] == "1 Haswell"


def test_makefile_exports_the_same_settings():
    mk = (ROOT / "Makefile").read_text()
    exported = dict(re.findall(r"^export (\w+) := (\S+)$", mk, flags=re.M))
    assert {k: exported.get(k) for k in blas.SETTINGS} == blas.SETTINGS
