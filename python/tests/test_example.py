"""examples/fig2.py runs and writes its figure (Agg backend, into a temporary directory)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fig2.py"


def test_fig2_example_writes_the_figure(tmp_path):
    out = tmp_path / "fig2.png"
    done = subprocess.run(
        [sys.executable, str(EXAMPLE), "--points", "16", "--out", str(out)],
        capture_output=True,
        text=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 0, done.stderr
    assert out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
