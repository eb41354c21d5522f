"""The Dask scale-out example (python/examples/dask_fit.py) on a LocalCluster of 2 workers: the
same camera files, statuses and messages as `camproj fit DIR -o OUT --jobs 2`."""
import glob
import json
import os
import subprocess

import pytest

from conftest import assert_same_json, run_cli

pytest.importorskip("distributed", reason="python3-distributed (scripts/install-deps.sh) is not installed")

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "examples", "dask_fit.py")


def table(stdout):
    """file -> (status, detail) of a batch table (header and totals dropped)."""
    rows = [line.split("\t") for line in stdout.splitlines()[1:-1]]
    return {os.path.basename(r[0]): (r[1], r[2]) for r in rows}


def test_dask_example_equals_the_batch_cli(cli, data_dir, tmp_path):
    # The 26 chessboard views: real planar data, some accepted, some refused (a single planar
    # view does not determine every intrinsic), so both outcomes are compared.
    folder = os.path.join(data_dir, "real", "opencv_chessboard")
    done_cli = run_cli(cli, "fit", folder, "-o", tmp_path / "cli", "--image-size", "640x480", "--jobs", "2")
    done_dask = subprocess.run(["/usr/bin/python3", EXAMPLE, folder, "-o", str(tmp_path / "dask"),
                                "--image-size", "640x480", "--workers", "2", "--files-per-task", "4"],
                               capture_output=True, text=True, timeout=120)
    assert done_dask.returncode == done_cli.returncode, done_dask.stderr
    assert table(done_dask.stdout) == table(done_cli.stdout)
    cli_files = sorted(os.listdir(tmp_path / "cli"))
    assert cli_files == sorted(os.listdir(tmp_path / "dask")) and cli_files
    for name in cli_files:
        with open(tmp_path / "cli" / name) as a, open(tmp_path / "dask" / name) as b:
            assert_same_json(json.load(b), json.load(a), name)
    assert len(cli_files) < len(glob.glob(os.path.join(folder, "*.csv"))) or "refused" not in done_cli.stdout
