#!/usr/bin/env python3
"""The paper's four-bar, driven at one revolution per second, force balanced by counterweights
on its crank and rocker: the shaking force before and after, as numbers and as a plot.

    python3 docs/examples/paper_fourbar_balance.py [PLOT.png]

Needs the module balance_design (built with balance-design; PYTHONPATH=build/python in the
source tree) and NumPy; the plot needs Matplotlib (python3-matplotlib) and is left out without
it. docs/python.md walks through it."""
import sys

import numpy as np

import balance_design as bd

# the study as Python dicts, with the keys of a study file (docs/study-format.md)
study = bd.study_from_dict({
    "name": "paper-fourbar-balance",
    "linkage": {
        "type": "fourbar", "frame": 3.2, "branch": 1,
        "crank":   {"length": 1.0, "mass": 2.1, "s": 0.6,  "sigma": 0.3,  "inertia": 1.1},
        "coupler": {"length": 3.0, "mass": 3.0, "s": 1.45, "sigma": 0.4,  "inertia": 3.1},
        "rocker":  {"length": 2.0, "mass": 2.2, "s": 1.66, "sigma": -0.4, "inertia": 2.1},
    },
    "scene": {"type": "driven", "theta1": 0.0, "omega1": 2 * np.pi,
              "revolutions": 1, "samples": 360},
    "balance": {"force": "full"},  # counterweights on crank and rocker: eq. 57 of the paper
})

result = study.run()  # what `balance-design run` computes; study.run("DIR") also writes its files
before, after = result.timeseries, result.balanced.timeseries
force_before = np.hypot(before["Fshx"], before["Fshy"])  # |Fsh| per sample [N]
force_after = np.hypot(after["Fshx"], after["Fshy"])

design = study.balanced_design()  # the balance step alone: what was added
for side in ("crank", "rocker"):
    cw = design[side + "_counterweight"]
    print(f"{side} counterweight: {cw['mass']:.4f} kg at {cw['distance']:.4f} m from its pivot")
print(f"RMS shaking force:  {result.metrics['Fsh_rms']:.4f} N before, "
      f"{result.balanced.metrics['Fsh_rms']:.3g} N after")
print(f"RMS shaking moment: {result.metrics['Msh_rms']:.4f} N m before, "
      f"{result.balanced.metrics['Msh_rms']:.4f} N m after "
      f"({result.balanced.metrics['Msh_rms'] / result.metrics['Msh_rms']:.2f} times)")
print(f"largest |Fsh| from the arrays: {force_before.max():.4f} N before, "
      f"{force_after.max():.3g} N after")

try:
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not found: no plot")
    sys.exit(0)
degrees = np.degrees(before["theta1"])
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(degrees, force_before, label="original")
ax.plot(degrees, force_after, label="force balanced")
ax.set_xlabel("crank angle θ1 [°]")
ax.set_ylabel("shaking force |Fsh| [N]")
ax.set_title("paper four-bar driven at 1 rev/s")
ax.legend()
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "paper-fourbar-balance.png"
fig.savefig(out)
print(f"plot: {out}")
