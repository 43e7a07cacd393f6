"""`vrw.animate`: the GIF (and the still PNG) of a Run or a gait, byte for byte the files `vrw animate` writes for
the same walk, with the command line's defaults and error messages."""

import re
import sys
import types

import pytest

import vrw
from conftest import cli_error

#: Small, quick options for the comparisons that are not about the defaults.
QUICK = {"fps": 10, "width": 320, "height": 180}


@pytest.fixture(scope="module")
def run():
    return vrw.simulate(vrw.Params(), steps=3)


@pytest.fixture(scope="module")
def run_dir(cli, tmp_path_factory):
    """`vrw simulate --steps 3`: the directory `vrw animate` draws."""
    out = tmp_path_factory.mktemp("simulate")
    cli("simulate", "--steps", 3, "--out", out)
    return out


def test_gif_is_the_cli_walk_gif_byte_for_byte(cli, run, run_dir, tmp_path):
    cli("animate", run_dir)
    written = vrw.animate(run, tmp_path / "walk.gif")
    assert written == tmp_path / "walk.gif"
    data = written.read_bytes()
    assert data.startswith(b"GIF89a")
    assert data == (run_dir / "walk.gif").read_bytes()


def test_options_are_the_cli_options(cli, run, run_dir, tmp_path):
    cli("animate", run_dir, "--fps", 10, "--width", 320, "--height", 180, "--from", 1, "--to", 3.5,
        "--speed", 0.5, "--horizontal")
    data = vrw.animate(run, tmp_path / "w.gif", from_=1, to=3.5, speed=0.5, horizontal=True, **QUICK)
    assert data.read_bytes() == (run_dir / "walk.gif").read_bytes()


def test_still_is_the_cli_png(cli, run, run_dir, tmp_path):
    cli("animate", run_dir, "--still", 2.0, "--width", 320, "--height", 180)
    png = vrw.animate(run, tmp_path / "frame.png", still=2.0, width=320, height=180).read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    assert png == (run_dir / "walk-frame.png").read_bytes()


def test_a_run_without_its_recorded_walk_or_trajectory_draws_the_same(run, monkeypatch):
    monkeypatch.setitem(sys.modules, "IPython", None)
    expected = vrw.animate(run, **QUICK)
    assert vrw.animate(vrw.simulate(vrw.Params(), steps=3, trajectory=False), **QUICK) == expected
    # Rebuilt from its fields (summary.json's): its config, initial and steps_requested, sample_dt 0.005 s.
    assert vrw.animate(vrw.Run(dict(run)), **QUICK) == expected


def test_gait_animates_two_periods_from_its_fixed_point(cli, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "IPython", None)
    params = vrw.Params()
    gait = vrw.find_gait(params)
    assert gait["period"] * 2 >= 2.0, "the default gait's two periods last 2 s: two periods are drawn"
    data = vrw.animate(gait, **QUICK)
    assert data.startswith(b"GIF89a")
    s = gait["section"]
    steps = 2 * gait["period_k"]
    cli("simulate", "--steps", steps, "--initial", f"{s['L2']!r},{s['thetadot']!r},{s['L2dot']!r}",
        "--out", tmp_path)
    cli("animate", tmp_path, *[a for k, v in QUICK.items() for a in (f"--{k}", v)])
    assert data == (tmp_path / "walk.gif").read_bytes()


def test_no_gait_is_not_drawn():
    lost = vrw.GaitResult(status="fell", message="Leg 1 fell", period_k=None)
    with pytest.raises(ValueError, match="found no gait"):
        vrw.animate(lost)
    with pytest.raises(TypeError, match="vrw.Run"):
        vrw.animate({"status": "completed"})


@pytest.mark.parametrize(
    "keywords, flags",
    [
        ({"fps": 0}, ["--fps", 0]),
        ({"fps": 60}, ["--fps", 60]),
        ({"speed": -1.0}, ["--speed", -1]),
        ({"width": 100}, ["--width", 100]),
        ({"from_": 3, "to": 1}, ["--from", 3, "--to", 1]),
        ({"speed": 1e-5}, ["--speed", 1e-5]),  # 13.8 million frames
        ({"from_": 50, "to": 60}, ["--from", 50, "--to", 60]),
    ],
)
def test_bad_options_are_the_cli_errors(cli, run, run_dir, keywords, flags):
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.animate(run, **keywords)
    expected = cli_error(cli("animate", run_dir, *flags, check=False))
    assert expected.startswith("animate: ")
    # The window is named by its file: the run directory's for the command line, the bare name here; the
    # settings by their flags there (`--fps`), by their fields here (`fps`).
    expected = expected[len("animate: "):].replace(f"{run_dir}/", "")
    for field in ["fps", "speed", "width", "height", "from", "to"]:
        expected = expected.replace(f"`--{field}`", f"`{field}`")
    expected = expected.replace("`--from/--to`", "`from/to`")
    assert "--" not in str(raised.value)
    assert str(raised.value) == expected


def test_bad_counts_are_named(run):
    with pytest.raises(vrw.ConfigError, match="`fps`"):
        vrw.animate(run, fps=-1)
    with pytest.raises(vrw.ConfigError, match="`width`"):
        vrw.animate(run, width=2**40)
    with pytest.raises(TypeError, match="`fps`"):
        vrw.animate(run, fps=2.5)


def test_without_a_path_an_image_for_the_notebook_or_the_bytes(run, monkeypatch):
    monkeypatch.setitem(sys.modules, "IPython", None)
    raw = vrw.animate(run, still=1.0, width=160, height=160)
    assert isinstance(raw, bytes) and raw.startswith(b"\x89PNG")

    class Image:
        def __init__(self, data, format):
            self.data, self.format = data, format

    display = types.ModuleType("IPython.display")
    display.Image = Image
    ipython = types.ModuleType("IPython")
    ipython.display = display
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    monkeypatch.setitem(sys.modules, "IPython.display", display)
    shown = vrw.animate(run, still=1.0, width=160, height=160)
    assert isinstance(shown, Image) and shown.format == "png" and shown.data == raw
    gif = vrw.animate(run, fps=2, width=160, height=160)
    assert gif.format == "gif" and gif.data.startswith(b"GIF89a")


def test_defaults_are_the_cli_defaults(cli):
    import inspect

    shown = dict(re.findall(r"--(\w+) <\w+>.*\[default: ([^\]]+)\]", cli("animate", "--help").stdout))
    for function in (vrw.animate, vrw._vrw.animate):
        defaults = {
            name: p.default for name, p in inspect.signature(function).parameters.items()
            if name in shown
        }
        assert set(defaults) == {"fps", "speed", "width", "height"}
        assert {k: float(v) for k, v in shown.items()} == defaults
