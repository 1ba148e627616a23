"""Shared fixtures of the cadclash Python tests (run by CTest as `python_pytest`).

CTest sets PYTHONPATH to the built package, CADCLASH_DATA_DIR to data/ and CADCLASH_EXE to the
built `cadclash` command line; the tests that need the CLI or data/external skip without them.
"""
import json
import os
import pathlib
import subprocess

import pytest

import cadclash

SOURCE_DIR = pathlib.Path(os.environ.get("CADCLASH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATA_DIR = pathlib.Path(os.environ.get("CADCLASH_DATA_DIR", SOURCE_DIR / "data"))
AS1 = DATA_DIR / "external" / "as1-tu-203.stp"


@pytest.fixture(scope="session")
def data_dir() -> pathlib.Path:
    return DATA_DIR


@pytest.fixture(scope="session")
def as1_path() -> pathlib.Path:
    if not AS1.is_file():
        pytest.skip(f"{AS1} is missing (scripts/setup.sh fetches data/external)")
    return AS1


@pytest.fixture(scope="session")
def as1(as1_path) -> cadclash.Model:
    """as1-tu-203.stp loaded once (eager, default deflection); tests must not move it."""
    return cadclash.load(as1_path)


@pytest.fixture(scope="session")
def boxes(data_dir):
    """box_a (0..1 cube) and box_near (0.5 away along x), one surface per face."""
    return [data_dir / "collide" / "box_a.obj", data_dir / "collide" / "box_near.obj"]


@pytest.fixture(scope="session")
def cli():
    """Runs `cadclash check ... --json` and returns the parsed report."""
    exe = os.environ.get("CADCLASH_EXE")
    if not exe or not os.path.isfile(exe):
        pytest.skip("CADCLASH_EXE is not set to the built cadclash tool")

    def run(tmp_path, *args):
        # --eager: the Python models compared with it load eagerly (load's default).
        out = tmp_path / "report.json"
        proc = subprocess.run([exe, "check", *map(str, args), "--eager", "--json", str(out), "--no-timings"],
                              capture_output=True, text=True)
        assert proc.returncode in (0, 3), proc.stderr
        return json.loads(out.read_text())

    return run


def json_pair_key(p: dict) -> tuple:
    """The CLI JSON pair in the shape of PairResult.key."""
    def side(s):
        return s.get("step_id", s.get("surface"))
    return (p["a"]["instance"], p["b"]["instance"], side(p["a"]), side(p["b"]), p["class"])
