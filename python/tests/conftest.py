"""Shared fixtures: the program (BD_PROGRAM), the source tree (BD_SOURCE_DIR), a scratch folder
(BD_TEST_DIR), and the program's own output folders, run once per session."""
import csv
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("BD_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
EXAMPLES = SOURCE / "studies" / "examples"


def program():
    path = os.environ.get("BD_PROGRAM")
    if not path:
        pytest.skip("BD_PROGRAM (the balance-design program) not set")
    return path


@pytest.fixture(scope="session")
def scratch(tmp_path_factory):
    base = os.environ.get("BD_TEST_DIR")
    if base:
        path = pathlib.Path(base)
        shutil.rmtree(path, ignore_errors=True)
        path.mkdir(parents=True)
        return path
    return tmp_path_factory.mktemp("bd")


@pytest.fixture(scope="session")
def cli_run(scratch):
    """cli_run(example) -> the folder where `balance-design run` wrote the example's outputs."""
    done = {}

    def run(example):
        if example not in done:
            out = scratch / ("cli-" + example.replace(".yaml", ""))
            subprocess.run([program(), "run", str(EXAMPLES / example), "--out", str(out)],
                           check=True, capture_output=True, text=True)
            done[example] = out
        return done[example]

    return run


def read_csv(path):
    """A CSV file of numbers as (header, 2-D array); float() gives the very doubles printed."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) if x != "" else np.nan for x in r] for r in rows[1:]])


def assert_identical(a, b):
    """Same shape and the same doubles, bit for bit (NaN where NaN)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert a.shape == b.shape
    assert np.array_equal(a.view(np.int64), b.view(np.int64)) or \
        np.array_equal(a, b, equal_nan=True), f"largest difference {np.nanmax(np.abs(a - b))}"


def without_wall_time(summary):
    """summary.json without the optimiser's wall time (its 'seconds' and the time in its
    'brief_report'), the one thing two runs of a study do not share."""
    import re
    opt = summary.get("optimize")
    if opt:
        opt.pop("seconds", None)
        if "brief_report" in opt:
            opt["brief_report"] = re.sub(r", [0-9.e+-]+ s,", ", _ s,", opt["brief_report"])
    return summary
