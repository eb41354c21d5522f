"""Shared fixtures: the built command line and the bundled data (ctest passes both through the
environment: python/CMakeLists.txt)."""
import json
import os
import subprocess

import pytest


def _required_path(variable):
    path = os.environ.get(variable)
    if not path:
        pytest.fail(f"{variable} is not set: run these tests through ctest (python/CMakeLists.txt)")
    return path


@pytest.fixture(scope="session")
def cli():
    return _required_path("CAMPROJ_CLI")


@pytest.fixture(scope="session")
def data_dir():
    return _required_path("CAMPROJ_DATA_DIR")


def run_cli(cli, *args):
    return subprocess.run([cli, *map(str, args)], capture_output=True, text=True)


# Same library code, same inputs: the cameras are expected to be identical. 1e-12 relative (to
# the largest entry of the array a number belongs to) is the bound; it would still hold
# if the two builds contracted a few operations differently (each costs ~1e-16 relative, and
# the fit's Jacobian condition of at most 1e6 amplifies it to ~1e-10 only for the worst-
# determined parameter, of which none is in the file at full weight). Fit times are not compared.
RELATIVE = 1e-12


def assert_same_json(a, b, path="", scale=None):
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), f"{path}: keys {sorted(a)} != {sorted(b)}"
        for key in a:
            if key == "time_ms":
                continue
            assert_same_json(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {a} != {b}"
        numbers = [abs(x) for x in a + b if isinstance(x, (int, float)) and not isinstance(x, bool)]
        list_scale = max(numbers) if numbers else None
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same_json(x, y, f"{path}[{i}]", list_scale)
    elif isinstance(a, float) or isinstance(b, float):
        reference = max(abs(a), abs(b), scale or 0.0)
        assert abs(a - b) <= RELATIVE * reference, f"{path}: {a!r} != {b!r}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def load_json(text):
    return json.loads(text)
