"""CSV tables of the program (sweep.csv, comparison.csv, pareto.csv) as dicts of columns."""
import csv
import io
import math

import numpy as np


def _number(field):
    if field == "":
        return math.nan
    return float(field)  # raises ValueError for text


def csv_columns(text):
    """A CSV text with a header as {column: values}: a float64 array where every field is a
    number (empty fields are NaN), else a list of str. float() reads the program's "%.17g" and
    shortest-round-trip numbers back to the same doubles."""
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    out = {}
    for k, name in enumerate(header):
        fields = [row[k] if k < len(row) else "" for row in body]
        try:
            out[name] = np.array([_number(f) for f in fields], dtype=np.float64)
        except ValueError:
            out[name] = fields
    return out


def read_csv(path):
    """csv_columns() of the file at `path`."""
    with open(path, newline="", encoding="utf-8") as f:
        return csv_columns(f.read())
