"""NumPy examples: what a user computes from the arrays agrees with the tool's own numbers, and
the core at one instant agrees with the samples of a run."""
import threading

import numpy as np
import pytest

import balance_design as bd
from conftest import EXAMPLES


@pytest.fixture(scope="module")
def driven():
    study = bd.load_study(str(EXAMPLES / "paper-fourbar-driven.yaml"))
    return study, study.run()


def test_rms_of_the_shaking_force_from_the_arrays(driven):
    _, r = driven
    ts = r.timeseries
    # the shaking force is the sum of the support reactions (no counter-rotations here)
    assert np.array_equal(ts["Fshx"], ts["RA0x"] + ts["RA3x"])
    magnitude = np.hypot(ts["Fshx"], ts["Fshy"])
    # the peak is resolved between the samples: at least the largest sample, and within the
    # parabola's reach of it at 360 samples per revolution
    assert np.max(magnitude) <= r.metrics["Fsh_max"]
    assert np.max(magnitude) == pytest.approx(r.metrics["Fsh_max"], rel=1e-3)
    # RMS over the revolution, as the metric is defined (the samples of one period)
    assert np.sqrt(np.mean(magnitude ** 2)) == pytest.approx(r.metrics["Fsh_rms"], rel=1e-12)
    assert r.array.shape == (len(ts["t"]), len(r.columns))
    assert r.array.dtype == np.float64


def test_one_instant_is_a_sample_of_the_run(driven):
    study, r = driven
    ts = r.timeseries
    for i in (0, 45, 200):
        for method in ("mass-matrix", "opened-loop", "complex-masses"):
            s = study.inverse_dynamics(ts["theta1"][i], ts["omega1"][i], 0.0, method=method)
            for name in ("theta2", "theta3", "RA0x", "RA3y", "Fshx", "Msh", "tau"):
                assert s[name] == pytest.approx(ts[name][i], rel=1e-11, abs=1e-11), (name, method)
    k = study.kinematics(1.0, 2.0, 0.5)
    lengths = [np.linalg.norm(k["A1"] - k["A0"]), np.linalg.norm(k["A2"] - k["A1"]),
               np.linalg.norm(k["A3"] - k["A2"]), np.linalg.norm(k["A3"] - k["A0"])]
    assert lengths == pytest.approx([1.0, 3.0, 2.0, 3.2], rel=1e-14)
    # forward dynamics with the drive torque of inverse dynamics as a load is the same motion:
    # free motion (tau = 0) gives an alpha1 whose inverse dynamics needs tau = 0
    f = study.forward_dynamics(1.0, 2.0)
    assert study.inverse_dynamics(1.0, 2.0, f["alpha1"])["tau"] == pytest.approx(0, abs=1e-11)


def test_free_motion_alpha_is_forward_dynamics():
    study = bd.load_study(str(EXAMPLES / "paper-fourbar.yaml"))
    ts = study.run().timeseries
    for i in (0, 100, 400):
        f = study.forward_dynamics(ts["theta1"][i], ts["omega1"][i])
        assert f["alpha1"] == pytest.approx(ts["alpha1"][i], rel=1e-10)
        assert f["RA0y"] == pytest.approx(ts["RA0y"][i], rel=1e-10)


def test_a_planar_instant_is_a_sample_of_its_run():
    engine = bd.load_study(str(EXAMPLES / "engine-slider-crank.yaml"))
    ts = engine.run().timeseries
    i = 30
    s = engine.inverse_dynamics(ts["theta_crank"][i], ts["omega_crank"][i], 0.0)
    for name in ("x_B", "Fshx", "Fshy", "Msh", "tau", "ROx"):
        assert s[name] == pytest.approx(ts[name][i], rel=1e-10, abs=1e-9), name
    k = engine.kinematics(ts["theta_crank"][i], ts["omega_crank"][i])
    assert set(k) <= set(s) and "x_B" in k and "Fshx" not in k
    assert k["x_B"] == pytest.approx(ts["x_B"][i], rel=1e-12)


def test_balance_step_and_principal_vectors():
    study = bd.load_study(str(EXAMPLES / "paper-fourbar-driven-force-balanced.yaml"))
    assert not study.check_balance()["force_balanced"]
    step = study.balanced_design()
    assert step["crank_counterweight"]["mass"] > 0 and step["rocker_counterweight"]["mass"] > 0
    assert step["added_mass"] == pytest.approx(step["crank_counterweight"]["mass"] +
                                               step["rocker_counterweight"]["mass"], rel=1e-14)
    assert step["conditions"]["force_balanced"]
    balanced = step["study"]
    assert balanced.check_balance()["force_balanced"]
    # balanced: the system centre of mass stands still, the frame set's a14 and a34 vanish
    pv = balanced.principal_vectors(0.7)
    assert np.allclose(pv["frame"]["a14"], 0, atol=1e-12)
    assert np.allclose(pv["frame"]["a34"], 0, atol=1e-12)
    assert np.max(np.abs(balanced.run().timeseries["Fshx"])) < 1e-10
    # the run's summary.json says the same counterweights, to the last digit
    cws = study.run().summary["balance"]["counterweights"]
    for cw in cws:
        mine = step[cw["link"] + "_counterweight"]
        assert (cw["mass"], cw["distance"]) == (mine["mass"], mine["distance"])
        assert cw["position"] == list(mine["position"])


def test_optimize_step_gives_the_runs_optimum():
    study = bd.load_study(str(EXAMPLES / "berkof-lowen-min-shaking-moment.yaml"))
    step = study.optimize()
    assert step["found"] and step["termination"] == "converged"
    run = study.run()
    # the step's variables and optimum are the run's (summary.json's), to the last digit
    variables = run.summary["optimize"]["variables"]
    assert step["variables"] == {v["name"]: v["value"] for v in variables}
    assert step["objective"] == run.summary["optimize"]["objective"]
    assert step["study"].run().metrics == run.optimized.metrics
    assert run.optimized.metrics["Fsh_rms"] < 1e-9 < run.metrics["Fsh_rms"]  # force balanced


def test_run_releases_the_gil():
    study = bd.load_study(str(EXAMPLES / "triple-rocker-free.yaml"))
    started, ticks = threading.Event(), [0]

    def work():
        started.set()
        for _ in range(3):
            study.run()

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    while t.is_alive():
        ticks[0] += 1
    t.join()
    assert ticks[0] > 1000


def test_help_is_useful():
    assert "FILE:LINE:COLUMN" in bd.load_study.__doc__
    assert "GIL" in bd.Study.run.__doc__
    assert "timeseries.csv" in bd.Result.timeseries.__doc__
    assert "progress" in bd.Study.sweep.__doc__
