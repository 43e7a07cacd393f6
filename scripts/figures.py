"""Every figure of docs/ that the README shows, with the README's commands that make it and its source data.

One declaration for the scripts in scripts/: `scripts/regenerate-figures` runs the commands, copies each
figure to `docs/NAME.png` and records the SHA-256 digest and size of each of its source data files in
`docs/figure-data.json`; `scripts/check-readme`, which runs every command of the README anyway, compares those
digests with the files the commands write today, so that a figure whose data changed is known to be stale.
(Digests, not copies: the data of the twenty figures is 13 MB, and every regeneration would add it to the
history again.)

A figure's `commands` are the README's own, as it shows them (`cargo run --release --` written `vrw`), run in
order from one directory (the repository's `readings/` linked in); `image` is the file the last of them
writes (in its `--out` directory, or the directory `animate`/`plot` is given), and `data` the files the figure
is drawn from. Trajectories (`trajectory.csv`, 0.1 to 3 MB) are left out of the data of the run figures: their
`steps.csv` and `summary.json` already change whenever the walk does. PNGs are not compared (their pixels
depend on the font rasteriser and the plotting crate, not only on the numbers). Every data file vrw writes is
reproducible (no wall-clock times), so the digests compare every byte.

Import it from a script in scripts/ with `sys.path.insert(0, str(Path(__file__).resolve().parent))`.
"""

from __future__ import annotations

import hashlib
import json
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
# The committed digests of each figure's source data: {NAME: {FILE: {"sha256": HEX, "bytes": N}}}.
DIGESTS = DOCS / "figure-data.json"
# `![alt](docs/NAME.png)` in the README.
README_IMAGE = re.compile(r"!\[[^\]]*\]\(docs/([^)/\s]+)\.png\)")
# Subcommands that read the directory they are given and write a figure into it (no data of their own).
READERS = ("animate", "plot")


def digest(content: bytes) -> dict[str, object]:
    """What `docs/figure-data.json` records of a data file: its SHA-256 and its size."""
    return {"sha256": hashlib.sha256(content).hexdigest(), "bytes": len(content)}


def load_digests() -> dict[str, dict[str, dict[str, object]]]:
    """The committed digests (empty if there are none yet)."""
    return json.loads(DIGESTS.read_text()) if DIGESTS.exists() else {}


def save_digests(digests: dict[str, dict[str, dict[str, object]]]) -> None:
    """Write `docs/figure-data.json`, figures and files in order (a stable diff)."""
    ordered = {name: dict(sorted(files.items())) for name, files in sorted(digests.items())}
    DIGESTS.write_text(json.dumps(ordered, indent=2) + "\n")


@dataclass(frozen=True)
class Figure:
    """docs/NAME.png: made by `commands` (vrw argument strings, as the README shows them)."""

    name: str
    commands: tuple[str, ...]
    image: str
    data: tuple[str, ...]
    note: str = ""

    def argv(self) -> list[list[str]]:
        """Each command as the argument list after `vrw`."""
        return [shlex.split(c) for c in self.commands]

    def producers(self) -> list[list[str]]:
        """The commands that write the data (not those that only draw from a directory: animate, plot)."""
        return [args for args in self.argv() if args[:1] and args[0] not in READERS]

    def data_files(self) -> list[tuple[str, str]]:
        """Each data file: its path in the directory the commands ran in, and its name in the digests."""
        return [(path, Path(path).name) for path in self.data]


def out_dir(args: list[str]) -> str:
    """Where a vrw command writes: `--out DIR` (default `out/SUBCOMMAND`), or the DIR of animate and plot."""
    if args[:1] and args[0] in READERS:
        return next((a for a in args[1:] if not a.startswith("-")), "")
    for k, arg in enumerate(args):
        if arg == "--out" and k + 1 < len(args):
            return args[k + 1]
        if arg.startswith("--out="):
            return arg[len("--out=") :]
    return f"out/{args[0]}" if args else ""


def _in(directory: str, *files: str) -> tuple[str, ...]:
    return tuple(f"{directory}/{f}" for f in files)


SWEEP = ("sweep.csv", "thresholds.json")
ORBIT = ("orbit.csv", "branch.csv", "orbit.json")
BASIN = ("basin.csv", "basin.json")
CONTINUE = ("branch.csv", "special_points.json")
MAP = ("map.csv", "curves.json")
RUN = ("steps.csv", "summary.json")  # not trajectory.csv (large); see the module's doc
LIGHT_HUB = "--set hub_mass=2 --set stiffness=300 --set slope=0.15 --set impact=traditional"
MARKS = '--mark "220,500,paper λ₄⁺ = 0" --mark "4,500,paper λ₂⁺ = 0"'

# In the README's order.
FIGURES: list[Figure] = [
    Figure("fig2", ("sweep",), "out/sweep/fig2.png", _in("out/sweep", *SWEEP)),
    Figure(
        "walk-frame",
        ("simulate", "animate out/simulate --still 3.27"),
        "out/simulate/walk-frame.png",
        _in("out/simulate", *RUN),
        "the --still command is in the prose under the image, not in the ```sh block",
    ),
    Figure("run", ("gait", "plot out/gait"), "out/gait/run.png", _in("out/gait", *RUN)),
    Figure(
        "orbit-bounce",
        ("orbit --param stiffness --from 570 --to 660 --set viscosity=20 --out out/orbit-bounce",),
        "out/orbit-bounce/orbit.png",
        _in("out/orbit-bounce", *ORBIT),
    ),
    Figure(
        "orbit",
        (f"orbit {LIGHT_HUB} --from 0.5 --to 12 --out out/orbit-p2",),
        "out/orbit-p2/orbit.png",
        _in("out/orbit-p2", *ORBIT),
    ),
    Figure("basin", ("basin",), "out/basin/basin.png", _in("out/basin", *BASIN)),
    Figure(
        "basin-period2",
        (f"basin {LIGHT_HUB} --set viscosity=3 --nx 121 --ny 121 --out out/basin-p2",),
        "out/basin-p2/basin.png",
        _in("out/basin-p2", *BASIN),
    ),
    Figure(
        "continue-viscosity",
        ("continue --plot period",),
        "out/continue/bifurcation.png",
        _in("out/continue", *CONTINUE),
    ),
    Figure(
        "continue-slope",
        ("continue --param slope --from 0.05 --to 0.35 --start 0.1 --out out/continue-slope",),
        "out/continue-slope/bifurcation.png",
        _in("out/continue-slope", *CONTINUE),
    ),
    Figure(
        "continue-light-hub",
        (f"continue {LIGHT_HUB} --from 0.5 --to 6 --start 3 --out out/continue-light-hub",),
        "out/continue-light-hub/bifurcation.png",
        _in("out/continue-light-hub", *CONTINUE),
        "no ```sh block: the command is the README's check comment (its prose shows it without --out)",
    ),
    Figure(
        "continue-stiffness",
        (
            "continue --param stiffness --set viscosity=20 --from 540 --to 650 --start 560 "
            "--out out/continue-stiffness",
        ),
        "out/continue-stiffness/bifurcation.png",
        _in("out/continue-stiffness", *CONTINUE),
    ),
    Figure(
        "continue-curve",
        (
            "continue --param stiffness --set viscosity=20 --from 540 --to 620 --start 560 --no-switch "
            "--two-param viscosity --two-range 4,25 --out out/continue-curve",
        ),
        "out/continue-curve/curves.png",
        _in("out/continue-curve", *CONTINUE, "curves.csv"),
    ),
    Figure(
        "orbit-simplest",
        (
            "orbit --model simplest --param slope --from 0.010 --to 0.019 --points 181 --transient 200 "
            "--steps 64 --out out/orbit-simplest",
        ),
        "out/orbit-simplest/orbit.png",
        _in("out/orbit-simplest", *ORBIT),
    ),
    Figure(
        "orbit-compass",
        (
            "orbit --model compass --param slope --from 0.06 --to 0.092 --points 129 --transient 100 "
            "--steps 32 --out out/orbit-compass",
        ),
        "out/orbit-compass/orbit.png",
        _in("out/orbit-compass", *ORBIT),
    ),
    Figure(
        "map-compass",
        (
            "map --model compass --x slope --x-from 0.04 --x-to 0.09 --nx 26 --y hip_mass --y-from 4 "
            "--y-to 20 --ny 17 --out out/compass-map",
        ),
        "out/compass-map/map.png",
        _in("out/compass-map", "map.csv", "map.json"),
    ),
    Figure(
        "basin-simplest",
        ("basin --model simplest --set slope=0.009 --nx 201 --ny 201 --out out/basin-simplest",),
        "out/basin-simplest/basin.png",
        _in("out/basin-simplest", *BASIN),
    ),
    Figure(
        "map-no-preload-k5000",
        (
            "map --config readings/no-preload.toml --y-from 300 --y-to 5000 --nx 31 --ny 36 "
            f"{MARKS} --out out/map-no-preload-k5000",
        ),
        "out/map-no-preload-k5000/map.png",
        _in("out/map-no-preload-k5000", *MAP),
    ),
    Figure(
        "map-stroke-limited-k5000",
        (
            "map --config readings/stroke-limited.toml --y-from 300 --y-to 5000 --nx 31 --ny 36 "
            f"{MARKS} --out out/map-stroke-limited-k5000",
        ),
        "out/map-stroke-limited-k5000/map.png",
        _in("out/map-stroke-limited-k5000", *MAP),
    ),
    Figure(
        "map-preload",
        (f"map --nx 100 --ny 100 {MARKS} --out out/map-preload",),
        "out/map-preload/map.png",
        _in("out/map-preload", *MAP),
    ),
    Figure(
        "map-no-preload",
        (f"map --nx 41 --ny 41 --set spring_natural_length=1.0 {MARKS} --out out/map-no-preload",),
        "out/map-no-preload/map.png",
        _in("out/map-no-preload", *MAP),
    ),
    Figure(
        "fig2-friction-0.6",
        ("sweep --set friction=0.6 --out out/sweep-friction-0.6",),
        "out/sweep-friction-0.6/fig2.png",
        _in("out/sweep-friction-0.6", *SWEEP),
    ),
    Figure(
        "fig2-friction-0.3",
        ("sweep --set friction=0.3 --out out/sweep-friction-0.3",),
        "out/sweep-friction-0.3/fig2.png",
        _in("out/sweep-friction-0.3", *SWEEP),
    ),
    Figure(
        "map-friction",
        ("map --y friction --y-from 0.1 --y-to 1.5 --ny 15 --nx 31 --no-curves --out out/map-friction",),
        "out/map-friction/map.png",
        _in("out/map-friction", *MAP),
    ),
    Figure(
        "map-friction-signatures",
        ("map --y friction --y-from 0.1 --y-to 1.5 --ny 15 --nx 31 --no-curves --out out/map-friction",),
        "out/map-friction/signatures.png",
        _in("out/map-friction", *MAP),
    ),
]

BY_NAME = {figure.name: figure for figure in FIGURES}
assert len(BY_NAME) == len(FIGURES), "two figures with one name"


def readme_images(readme: str) -> list[str]:
    """The names NAME of the `![...](docs/NAME.png)` images of the README, in order, each once."""
    return list(dict.fromkeys(README_IMAGE.findall(readme)))


def readme_commands(readme: str) -> set[tuple[str, ...]]:
    """Every vrw argument list the README shows: in its ```sh blocks, its check comments and its inline code.

    A declared command must be one of them (the declaration follows the README; see check-readme).
    """
    text = re.sub(r"\\\n\s*", " ", readme)
    shown: set[tuple[str, ...]] = set()
    prose = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    candidates = re.findall(r"`([^`]+)`", prose.replace("\n", " "))  # inline code, across line breaks
    candidates += re.findall(r"<!--\s*check:\s*(.*?)\s*(?:=>.*?)?-->", text, re.S)
    candidates += [line.split(" #", 1)[0] for line in text.splitlines()]  # lines of the ```sh blocks
    for candidate in candidates:
        for part in candidate.split("&&"):
            try:
                words = shlex.split(" ".join(part.split()))
            except ValueError:
                continue
            if words[:4] == ["cargo", "run", "--release", "--"]:
                shown.add(tuple(words[4:]))
            elif words[:1] == ["vrw"]:
                shown.add(tuple(words[1:]))
    return shown
