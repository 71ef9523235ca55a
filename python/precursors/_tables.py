"""CSV tables (a run's or a merge's) as dicts of numpy columns."""

import csv
from pathlib import Path
from typing import Dict, Union

import numpy as np


def read_table(path: Union[str, Path]) -> Dict[str, np.ndarray]:
    """The columns of a CSV table by header name: float64 where every cell is a number
    (an empty cell is NaN), else an array of strings."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns: Dict[str, np.ndarray] = {}
    for j, name in enumerate(header):
        cells = [row[j] if j < len(row) else "" for row in body]
        try:
            columns[name] = np.array(
                [float(c) if c != "" else np.nan for c in cells], dtype=np.float64
            )
        except ValueError:
            columns[name] = np.array(cells, dtype=str)
    return columns
