"""The module against the program's own output files, to the last digit: every study computed
by Study.run() gives the numbers, dicts and texts the program writes for it."""
import csv
import json

import numpy as np
import pytest

import balance_design as bd
from conftest import EXAMPLES, assert_identical, read_csv, without_wall_time

CASES = [
    "paper-fourbar.yaml",                        # four-bar, free motion (CVODE)
    "paper-fourbar-driven-force-balanced.yaml",  # four-bar, driven, balance section
    "engine-slider-crank-balanced.yaml",         # planar linkage, least-squares counterweight
    "berkof-lowen-min-shaking-moment.yaml",      # four-bar, optimize section
]


@pytest.fixture(scope="module")
def runs(cli_run):
    return {name: (bd.load_study(str(EXAMPLES / name)).run(), cli_run(name)) for name in CASES}


@pytest.mark.parametrize("name", CASES)
def test_timeseries_are_the_programs_to_the_last_digit(runs, name):
    result, out = runs[name]
    header, values = read_csv(out / "timeseries.csv")
    assert result.columns == header
    assert list(result.timeseries) == header
    assert_identical(result.array, values)
    for k, column in enumerate(header):
        assert_identical(result.timeseries[column], values[:, k])


@pytest.mark.parametrize("name", CASES)
def test_summary_is_summary_json(runs, name):
    result, out = runs[name]
    with open(out / "summary.json") as f:
        written = json.load(f)
    assert without_wall_time(result.summary) == without_wall_time(written)
    assert result.metrics == written["metrics"]
    assert list(result.metrics) == list(written["metrics"])
    assert result.ok and not result.stopped_early and result.status == "completed"


@pytest.mark.parametrize("name", ["paper-fourbar-driven-force-balanced.yaml",
                                  "engine-slider-crank-balanced.yaml"])
def test_balanced_design_is_the_programs(runs, name):
    result, out = runs[name]
    assert result.optimized is None
    b = result.balanced
    header, values = read_csv(out / "balanced-timeseries.csv")
    assert b.columns == header
    assert_identical(b.array, values)
    assert b.yaml == (out / "balanced.yaml").read_text()
    assert b.metrics == json.loads((out / "summary.json").read_text())["balanced_metrics"]
    comparison = (out / "comparison.csv").read_text().splitlines()
    assert list(result.comparison["metric"]) == [line.split(",")[0] for line in comparison[1:]]
    _, numbers = read_csv_numbers(out / "comparison.csv")
    assert_identical(np.column_stack([result.comparison[c] for c in ("before", "after", "ratio")]),
                     numbers)
    # the design as a Study of its own, run again: the same samples
    again = b.study.run()
    assert_identical(again.array, values)


def read_csv_numbers(path):
    lines = path.read_text().splitlines()
    rows = [line.split(",")[1:] for line in lines[1:]]
    return lines[0], np.array([[float(x) if x else np.nan for x in r] for r in rows])


def test_optimum_is_the_programs(runs):
    result, out = runs["berkof-lowen-min-shaking-moment.yaml"]
    assert result.balanced is None
    o = result.optimized
    header, values = read_csv(out / "optimized-timeseries.csv")
    assert_identical(o.array, values)
    assert o.yaml == (out / "optimized.yaml").read_text()
    summary = json.loads((out / "summary.json").read_text())
    assert o.metrics == summary["optimized_metrics"]
    assert result.summary["optimize"]["seconds"] > 0
    assert without_wall_time(result.summary)["optimize"] == without_wall_time(summary)["optimize"]


def test_files_written_by_the_module_are_the_programs(scratch, cli_run):
    name = "paper-fourbar-driven-force-balanced.yaml"
    out = scratch / "module-driven-balanced"
    result = bd.run(str(EXAMPLES / name), out)
    assert result.ok
    for f in ["timeseries.csv", "summary.json", "balanced-timeseries.csv", "balanced.yaml",
              "comparison.csv", "harmonics.csv"]:
        assert (out / f).read_bytes() == (cli_run(name) / f).read_bytes(), f


def test_a_study_from_dicts_is_the_study_from_its_file():
    from_file = bd.load_study(str(EXAMPLES / "paper-fourbar-driven.yaml"))
    keys = ("length", "mass", "s", "sigma", "inertia")
    links = {"crank": (1.0, 2.1, 0.6, 0.3, 1.1), "coupler": (3.0, 3.0, 1.45, 0.4, 3.1),
             "rocker": (2.0, 2.2, 1.66, -0.4, 2.1)}
    linkage = {"type": "fourbar", "frame": 3.2, "branch": 1}
    linkage.update({name: dict(zip(keys, values)) for name, values in links.items()})
    d = {"name": "paper-fourbar-driven", "linkage": linkage,
         "scene": {"type": "driven", "theta1": 0.0, "omega1": 2 * np.pi,
                   "revolutions": 1, "samples": np.int64(360)}}
    from_dict = bd.study_from_dict(d)
    assert from_dict.source == "<dict>"
    assert from_dict.yaml == from_file.yaml
    assert_identical(from_dict.run().array, from_file.run().array)
    # and back: the study's own YAML text reads back to the same study
    assert bd.parse_study(from_dict.yaml).yaml == from_dict.yaml


def test_a_sweep_table_is_sweep_csv_and_reports_progress(scratch, cli_run):
    text = (EXAMPLES / "paper-fourbar-sweep.yaml").read_text().replace("count: 21", "count: 3")
    study = bd.parse_study(text, "small-sweep.yaml")
    assert study.has_sweep
    calls = []
    result = study.sweep(scratch / "sweep-module", progress=calls.append, threads=2)
    assert result.complete and result.points == 9 and result.done == 9 and result.failed == 0
    assert [c["done"] for c in calls if not c["finished"]] == list(range(1, 10))
    assert calls[-1]["finished"] and calls[-1]["done"] == 9
    table = result.table
    with open(result.csv, newline="") as f:
        rows = list(csv.reader(f))
    assert list(table) == rows[0]
    for k, column in enumerate(rows[0]):
        if column not in ("status", "message"):
            assert_identical(table[column], [float(r[k]) if r[k] else np.nan for r in rows[1:]])
    assert table["status"] == ["ok"] * 9
    assert_identical(table["linkage.coupler.mass"], [1, 1, 1, 3, 3, 3, 5, 5, 5])
    # every metric as the point's own run gives it
    point = bd.parse_study(text.split("\nsweep:")[0].replace("mass: 3.0", "mass: 5.0")
                           .replace("s: 1.45", "s: 2.5"), "point.yaml")
    last = point.run()
    for metric, value in last.metrics.items():
        assert table[metric][-1] == value
        assert table["balanced_" + metric][-1] == last.balanced.metrics[metric]
