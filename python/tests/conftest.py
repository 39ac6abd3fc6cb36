# pytest set-up for the Python module's tests (run by scripts/test.sh):
#   PYTHONPATH=build/python python3 -m pytest python/tests
# The module must come from the build (or an install): the tests fail, they do not skip, when
# it cannot be imported. SPHEREKIT_EXE overrides the command line the results are compared with.
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("SPHEREKIT_EXE", str(ROOT / "build" / "tools" / "cli" / "spherekit"))
    assert os.access(path, os.X_OK), f"the spherekit program is not built at {path} (scripts/build.sh)"
    return path


@pytest.fixture(scope="session")
def samples(exe, tmp_path_factory):
    """Three small built-in samples written by `spherekit samples` (meshes + landmark files)."""
    out = tmp_path_factory.mktemp("samples")
    subprocess.run([exe, "samples", "-o", str(out), "--members", "3", "--vertices", "700"], check=True,
                   stdout=subprocess.DEVNULL)
    return out


def cli_error(exe, *args):
    """Runs the command line, expects it to fail, returns (exit code, the message of its one error line)."""
    r = subprocess.run([exe, *args], capture_output=True, text=True)
    assert r.returncode != 0, r.stdout
    lines = [line for line in r.stderr.splitlines() if line.startswith("spherekit: error: ")]
    assert len(lines) == 1, r.stderr
    return r.returncode, lines[0][len("spherekit: error: "):]
