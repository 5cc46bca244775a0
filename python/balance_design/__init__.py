"""balance-design from Python: shaking-force and shaking-moment balancing of planar linkages.

Load or build a study, run it as the program does, and read the results as NumPy arrays and
plain dicts::

    import balance_design as bd
    study = bd.load_study("studies/examples/paper-fourbar-driven-force-balanced.yaml")
    result = study.run()                      # or study.run("results/x"): the program's files too
    result.timeseries["Fshx"]                 # NumPy array, one value per sample
    result.metrics["Fsh_rms"], result.balanced.metrics["Fsh_rms"]
    result.summary["balance"]                 # summary.json as a dict

Studies come from a file (load_study), YAML text (parse_study) or Python dicts
(study_from_dict); mistakes raise StudyError with the program's one-line message
"FILE:LINE:COLUMN: message". Study also gives the core at one instant (kinematics,
inverse_dynamics, forward_dynamics, principal_vectors) and the balance and optimise steps
(check_balance, balanced_design, optimize). docs/python.md has the whole tour.
"""
import json
import math
import numbers
import re

import numpy as np

from ._balance_design import (  # noqa: F401  (the module's public names)
    DesignRun,
    DynamicsError,
    InputError,
    Result,
    Study,
    StudyError,
    SweepResult,
    __version__,
    load_study,
    parse_study,
)

__all__ = [
    "DesignRun", "DynamicsError", "InputError", "Result", "Study", "StudyError", "SweepResult",
    "load_study", "parse_study", "study_from_dict", "study_yaml_text", "run",
]

_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_.-]*$")


def _scalar(value):
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        value = float(value)
        if math.isfinite(value):
            return repr(value)  # the shortest text that reads back to the same double
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf")
    return json.dumps(str(value))  # a JSON string is a YAML double-quoted scalar


def _key(key):
    key = str(key)
    return key if _PLAIN.match(key) else json.dumps(key)


def _is_flat(seq):
    return all(not isinstance(v, (dict, list, tuple)) for v in seq)


def _lines(value, indent):
    pad = " " * indent
    out = []
    if isinstance(value, dict):
        for k, v in value.items():
            if isinstance(v, dict) and v:
                out.append(f"{pad}{_key(k)}:")
                out += _lines(v, indent + 2)
            elif isinstance(v, (list, tuple)) and v and not _is_flat(v):
                out.append(f"{pad}{_key(k)}:")
                out += _lines(list(v), indent + 2)
            else:
                out.append(f"{pad}{_key(k)}: {_inline(v)}")
    else:  # a list with dicts or lists in it
        for v in value:
            if isinstance(v, dict) and v:
                inner = _lines(v, indent + 2)
                out.append(f"{pad}- {inner[0].lstrip()}")
                out += inner[1:]
            else:
                out.append(f"{pad}- {_inline(v)}")
    return out


def _inline(value):
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)}: {_inline(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        value = value.tolist() if hasattr(value, "tolist") else value
        if not isinstance(value, list):
            return _scalar(value)
        return "[" + ", ".join(_inline(v) for v in value) + "]"
    return _scalar(value)


def study_yaml_text(study):
    """The YAML text study_from_dict() reads for a dict: one key per line, in the dict's order,
    lists of numbers inline, floats written by repr() (the same double when read back)."""
    if not isinstance(study, dict):
        raise TypeError("a study is a dict of its sections (name, linkage, scene, ...)")
    return "\n".join(_lines(study, 0)) + "\n"


def study_from_dict(study, name="<dict>"):
    """Builds a study from Python dicts and lists with the keys of a study file
    (docs/study-format.md), e.g.::

        bd.study_from_dict({
            "name": "fourbar",
            "linkage": {"type": "fourbar", "frame": 3.2,
                        "crank": {"length": 1.0, "mass": 2.1, "s": 0.6, "sigma": 0.3, "inertia": 1.1},
                        ...},
            "scene": {"type": "driven", "theta1": 0.0, "omega1": 6.283185307179586},
            "balance": {"force": "full"}})

    It is written as YAML (study_yaml_text(), one key per line) and read by parse_study(), so
    every check of a study file applies; a StudyError's line and column point into that text and
    its message names the key, e.g. "<dict>:7:34: coupler.mass must be > 0 kg, got -3".
    NumPy numbers and arrays are accepted where numbers and lists are."""
    return parse_study(study_yaml_text(study), name)


def run(study, out_dir=None):
    """Runs a Study, or the study file at a path, as `balance-design run` does: Study.run()."""
    if not isinstance(study, Study):
        study = load_study(study)
    return study.run(out_dir)
