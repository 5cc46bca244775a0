"""The program's mistakes as Python exceptions, with the very line the program prints."""
import subprocess

import pytest

import balance_design as bd
from conftest import EXAMPLES, program

BAD = """name: bad
linkage:
  type: fourbar
  frame: 3.2
  branch: 1
  crank:   {length: 1.0, mass: 2.1, s: 0.6, sigma: 0.3, inertia: 1.1}
  coupler: {length: 3.0, mass: -1, s: 1.45, sigma: 0.4, inertia: 3.1}
  rocker:  {length: 2.0, mass: 2.2, s: 1.66, sigma: -0.4, inertia: 2.1}
scene: {type: free, duration: 1}
"""


def test_a_bad_study_file_raises_the_programs_line(scratch):
    path = scratch / "bad.yaml"
    path.write_text(BAD)
    cli = subprocess.run([program(), "run", str(path), "--out", str(scratch / "bad-out")],
                         capture_output=True, text=True)
    assert cli.returncode == 2
    with pytest.raises(bd.StudyError) as e:
        bd.load_study(str(path))
    assert str(e.value) + "\n" == cli.stderr
    assert str(e.value) == f"{path}:7:32: linkage.coupler.mass must be > 0 kg, got -1"
    assert (e.value.file, e.value.line, e.value.column) == (str(path), 7, 32)
    assert e.value.message == "linkage.coupler.mass must be > 0 kg, got -1"
    assert isinstance(e.value, bd.InputError) and isinstance(e.value, ValueError)


@pytest.mark.parametrize("text, expected", [
    ("name: x\nlinkage: {type: fourbar, frame: 3.2, bogus: 1}\n",
     "<string>:1:1: missing required key 'scene'"),
    ("name: x\nlinkage: {type: fourbar, frame: 3.2, branch: 1, bogus: 1}\nscene: {type: driven}\n",
     "<string>:2:"),
    ("name: x\nlinkage: [unclosed\n", "<string>:"),
    ("", "<string>"),
])
def test_bad_text_raises_study_error_with_its_place(text, expected):
    with pytest.raises(bd.StudyError) as e:
        bd.parse_study(text)
    assert str(e.value).startswith(expected)
    assert "\n" not in str(e.value)


def test_a_dict_with_a_mistake_names_the_key_and_its_line():
    study = {
        "name": "d",
        "linkage": {
            "type": "fourbar", "frame": 3.2, "branch": 1,
            "crank": {"length": 1.0, "mass": 2.1, "s": 0.6, "sigma": 0.3, "inertia": 1.1},
            "coupler": {"length": 3.0, "mass": -3, "s": 1.45, "sigma": 0.4, "inertia": 3.1},
            "rocker": {"length": 2.0, "mass": 2.2, "s": 1.66, "sigma": -0.4, "inertia": 2.1},
        },
        "scene": {"type": "driven"},
    }
    with pytest.raises(bd.StudyError) as e:
        bd.study_from_dict(study)
    assert e.value.message == "linkage.coupler.mass must be > 0 kg, got -3"
    assert e.value.file == "<dict>"
    lines = bd.study_yaml_text(study).splitlines()
    assert lines[e.value.line - 1] == "    mass: -3"  # coupler's, one key per line
    assert lines[e.value.line - 1][e.value.column - 1:] == "-3"
    with pytest.raises(TypeError):
        bd.study_from_dict("not a dict")


def test_a_missing_file():
    with pytest.raises(bd.StudyError) as e:
        bd.load_study("/nonexistent/study.yaml")
    assert str(e.value).startswith("/nonexistent/study.yaml: ")


def test_dynamics_errors_at_one_instant():
    rocker = bd.load_study(str(EXAMPLES / "triple-rocker-free.yaml"))
    with pytest.raises(bd.DynamicsError, match="loop cannot close at theta1 = 3.14"):
        rocker.inverse_dynamics(3.14159, 1.0)
    with pytest.raises(bd.DynamicsError):
        rocker.kinematics(3.14159)
    with pytest.raises(bd.InputError, match="method must be"):
        rocker.inverse_dynamics(0.0, 1.0, method="truss-dae")
    engine = bd.load_study(str(EXAMPLES / "engine-slider-crank.yaml"))
    with pytest.raises(bd.InputError, match="rate: 1 value"):
        engine.inverse_dynamics(0.5, [1.0, 2.0])
    with pytest.raises(bd.InputError, match="four-bar"):
        engine.principal_vectors(0.0)


def test_steps_a_study_lacks():
    plain = bd.load_study(str(EXAMPLES / "paper-fourbar-driven.yaml"))
    with pytest.raises(bd.InputError, match="no optimize section"):
        plain.optimize()
    with pytest.raises(bd.InputError, match="no balance section"):
        plain.balanced_design()
    with pytest.raises(bd.InputError, match="no sweep section"):
        plain.sweep("/tmp/never-written")
    sweep = bd.load_study(str(EXAMPLES / "paper-fourbar-sweep.yaml"))
    with pytest.raises(bd.InputError, match="sweep section"):
        sweep.run()


def test_a_progress_callback_that_raises_stops_the_sweep(scratch):
    text = (EXAMPLES / "paper-fourbar-sweep.yaml").read_text().replace("count: 21", "count: 8")
    study = bd.parse_study(text, "stopped-sweep.yaml")  # 64 points, one at a time
    out = scratch / "stopped-sweep"

    class Enough(Exception):
        pass

    def stop_after_two(p):
        if p["done"] >= 2 and not p["finished"]:
            raise Enough()

    with pytest.raises(Enough):
        study.sweep(out, progress=stop_after_two, threads=1)
    with pytest.raises(bd.InputError, match="resume"):
        study.sweep(out)  # unfinished: the program's message says to resume
    done = study.sweep(out, resume=True, threads=1)
    assert done.complete and 2 <= done.resumed < 64 and done.points == 64 and done.failed == 0
