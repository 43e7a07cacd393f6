"""Shared fixtures: the command-line binary the Python front is compared with, and CSV readers."""

import csv
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Run the `vrw` command line (`$VRW_CLI`, or target/release/vrw built by cargo if needed)."""
    path = os.environ.get("VRW_CLI")
    if not path:
        subprocess.run(
            ["cargo", "build", "--release", "--quiet", "--bin", "vrw"], cwd=ROOT, check=True
        )
        path = str(ROOT / "target" / "release" / "vrw")

    def run(*args, check=True):
        done = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"vrw {' '.join(map(str, args))} failed:\n{done.stderr}")
        return done

    return run


def cli_error(done):
    """The message of a failed command (`Error: <message>` on stderr)."""
    assert done.returncode == 1, done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith("Error: "), line
    return line[len("Error: ") :]


def read_csv(path):
    """A CSV file as (header, rows of strings)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def same_float(a, b):
    """The same float (NaN equals NaN; -0 equals 0, since the CSV writes both as `0`)."""
    return (math.isnan(a) and math.isnan(b)) or a == b


def assert_table_equals_csv(table, path):
    """The dict of arrays `table` holds exactly the CSV file's columns and values (compared at full
    precision: the CSV writes the shortest text that reads back to the same float)."""
    header, rows = read_csv(path)
    assert list(table.keys()) == header
    for j, name in enumerate(header):
        column = table[name]
        assert len(column) == len(rows), name
        for i, row in enumerate(rows):
            text, value = row[j], column[i]
            kind = column.dtype.kind
            if kind == "f":
                expected = float(text) if text != "" else math.nan
                assert same_float(float(value), expected), (name, i, text, value)
            elif kind == "b":
                assert text in ("true", "false", ""), (name, i, text)
                assert bool(value) == (text == "true"), (name, i, text, value)
            elif kind in "iu":
                assert int(value) == (int(text) if text != "" else 0), (name, i, text, value)
            else:
                assert str(value) == text, (name, i, text, value)


def json_equal(python, json_value):
    """A Python result equals the JSON value (JSON writes NaN as null; arrays as lists)."""
    if isinstance(python, np.ndarray):
        if python.dtype.kind == "c":
            python = [[z.real, z.imag] for z in python]
        else:
            python = python.tolist()
    if isinstance(python, dict):
        return isinstance(json_value, dict) and python.keys() == json_value.keys() and all(
            json_equal(python[k], json_value[k]) for k in python
        )
    if isinstance(python, (list, tuple)):
        return len(python) == len(json_value) and all(
            json_equal(a, b) for a, b in zip(python, json_value)
        )
    if isinstance(python, float) and math.isnan(python):
        return json_value is None
    if isinstance(python, float) and not isinstance(json_value, bool) and isinstance(json_value, (int, float)):
        return same_float(python, float(json_value))
    return python == json_value
