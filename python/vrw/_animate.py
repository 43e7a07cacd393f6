"""``vrw.animate``: the animation of ``vrw animate`` (or its still frame) of a ``Run`` or a ``GaitResult``,
written to a file or shown in a notebook."""

import math
import os
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Union

from . import _vrw
from ._vrw import Params
from .results import GaitResult, Run

__all__ = ["animate"]

#: A gait is animated over at least this many periods ...
GAIT_PERIODS = 2
#: ... and over at least this many seconds of walking (whole periods).
GAIT_SECONDS = 2.0
#: The sampling interval of a walk that does not say its own [s]: ``vrw.simulate``'s and ``vrw gait``'s.
SAMPLE_DT = 0.005

#: What ``vrw.simulate`` records in a ``Run`` (an attribute, not a field of ``summary.json``): the walk's
#: arguments, so that ``animate`` walks it again bit for bit.
WALK_ATTRIBUTE = "_walk"


#: What ``vrw.find_gait`` records in a walker's ``GaitResult`` (an attribute, not a field of ``gait.json``): the
#: ``Params`` it searched with, for ``animate`` (a described walker's result names its model, not its file).
PARAMS_ATTRIBUTE = "_params"

#: The walkers built in, whose results rebuild their ``Params`` from ``model`` and ``parameters``.
BUILT_IN_WALKERS = ("simplest", "compass", "telescopic")


def record_walk(run: Run, params: Params, steps: int, initial: Any, sample_dt: float) -> None:
    """Keep the arguments ``vrw.simulate`` walked ``run`` with, for ``animate``."""
    setattr(run, WALK_ATTRIBUTE, {"params": params, "steps": steps, "initial": initial, "sample_dt": sample_dt})


def record_params(gait: GaitResult, params: Params) -> None:
    """Keep the ``Params`` ``vrw.find_gait`` searched ``gait`` with, for ``animate``."""
    setattr(gait, PARAMS_ATTRIBUTE, params)


def _section(state: Mapping[str, float], model: str) -> List[float]:
    """A section state of ``summary.json`` or ``gait.json`` as the ``initial`` of a walk: the wheel's
    ``{"L2", "thetadot", "L2dot", ...}``, or another walker's coordinates in their order."""
    if model != "vrw":
        return list(state.values())
    return [state["L2"], state["thetadot"], state["L2dot"]]


def _params_of(result: Mapping[str, Any], model: str) -> Params:
    """The ``Params`` of a result: recorded by ``vrw.find_gait``, or rebuilt from its ``config`` (the wheel)
    or its ``model`` and ``parameters`` (a built-in walker)."""
    recorded = getattr(result, PARAMS_ATTRIBUTE, None)
    if isinstance(recorded, Params):
        return recorded
    if model == "vrw":
        return Params(**result["config"])
    if model in BUILT_IN_WALKERS:
        return Params(model=model, **result["parameters"])
    raise ValueError(
        f"the result of the described walker `{model}` does not say which file describes it: animate the result "
        f"vrw.simulate or vrw.find_gait returned, or vrw.simulate(vrw.Params(model=PATH, ...), initial=...)"
    )


def _walk_of(run_or_gait: Mapping[str, Any]) -> Dict[str, Any]:
    """The arguments of the walk to draw (see ``animate``)."""
    recorded = getattr(run_or_gait, WALK_ATTRIBUTE, None)
    model = run_or_gait.get("model", "vrw")
    if isinstance(run_or_gait, Run) and isinstance(recorded, dict):
        return recorded
    if isinstance(run_or_gait, GaitResult) or "period_k" in run_or_gait or "newton_iterations" in run_or_gait:
        if run_or_gait.get("status") != "found":
            raise ValueError(
                f"the gait search found no gait ({run_or_gait.get('status')}: {run_or_gait.get('message')}): "
                "there is no walk to draw"
            )
        # Another walker's gaits are of period 1.
        k = run_or_gait.get("period_k", 1)
        cycle = run_or_gait.get("cycle") or []
        duration = sum(step["period"] for step in cycle) or k * run_or_gait["period"]
        periods = max(GAIT_PERIODS, math.ceil(GAIT_SECONDS / duration))
        return {
            "params": _params_of(run_or_gait, model),
            "steps": periods * k,
            "initial": _section(run_or_gait["section"], model),
            "sample_dt": SAMPLE_DT,
        }
    if isinstance(run_or_gait, Run) or "steps_requested" in run_or_gait:
        return {
            "params": _params_of(run_or_gait, model),
            "steps": run_or_gait["steps_requested"],
            "initial": _section(run_or_gait["initial"], model),
            "sample_dt": SAMPLE_DT,
        }
    raise TypeError(
        f"animate draws a vrw.Run (vrw.simulate) or a vrw.GaitResult (vrw.find_gait), not a "
        f"{type(run_or_gait).__name__}"
    )


def animate(
    run_or_gait: Union[Run, GaitResult],
    path: Union[str, "os.PathLike[str]", None] = None,
    *,
    fps: int = 25,
    speed: float = 1.0,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    width: int = 640,
    height: int = 360,
    horizontal: bool = False,
    still: Optional[float] = None,
) -> Any:
    """The walk as an animated GIF, as ``vrw animate DIR`` draws it (``walk.gif``), or with ``still`` (a time
    [s]) its single frame at that time as a PNG (``vrw animate --still TIME``, ``walk-frame.png``).

    What is drawn:

    - a ``Run`` (``vrw.simulate``) is walked again with the parameters, steps, initial state and
      ``sample_dt`` it was simulated with (``vrw.simulate`` keeps them with the run; its trajectory need not
      have been kept), so the GIF is, byte for byte, the ``walk.gif`` of ``vrw simulate`` with the same
      arguments followed by ``vrw animate``. A ``Run`` rebuilt from its fields alone (e.g. a plain dict of
      ``summary.json``) is walked from its ``config``, ``initial`` and ``steps_requested`` with the default
      ``sample_dt`` of 0.005 s;
    - a ``GaitResult`` (``vrw.find_gait``) found is walked from its fixed point ``section`` with its
      ``config``, sampled every 0.005 s as ``vrw gait`` samples its period: two periods of ``period_k``
      steps, or as many more whole periods as make at least 2 s of walking (``vrw gait``'s own directory
      holds one period). A search that found no gait raises ``ValueError``.

    Another walker's (``vrw.Params(model=...)``) ``Run`` or ``GaitResult`` is walked the same way (its gait of
    period 1, in the model's time unit) and drawn as ``vrw animate`` draws the directory of ``vrw simulate
    --model`` with those arguments: its stick figure (legs, masses, feet, the springs of compliant legs). Its
    ``Params`` are those the result was computed with; a result rebuilt from its fields alone gets them from
    its ``model`` and ``parameters`` (a built-in walker; a described walker's result names no file).

    The options are the command line's, with its defaults: ``fps`` (frames per second of playback, 1 to 50),
    ``speed`` (simulated seconds per second of playback), ``from_`` and ``to`` (the window of simulated time
    [s], default the whole walk; ``--from``/``--to``), ``width`` and ``height`` (pixels, 160 to 4000),
    ``horizontal`` (draw the slope horizontal). An option out of range, an animation of more than 90000
    frames or a window (or a ``still`` time) outside the walk raises ``vrw.ConfigError`` with the command
    line's message.

    With ``path``, the GIF (the PNG with ``still``) is written there and its ``pathlib.Path`` is returned.
    Without, the image is returned for a notebook to show: an ``IPython.display.Image`` (whose ``data`` is
    the bytes) if IPython can be imported, else the bytes of the file. The walk and the drawing run in Rust
    with the GIL released; Ctrl-C raises ``KeyboardInterrupt``.

    >>> import vrw
    >>> gif = vrw.animate(vrw.simulate(vrw.Params(), steps=3), "walk.gif")  # doctest: +SKIP
    """
    walk = _walk_of(run_or_gait)
    data = _vrw.animate(
        walk["params"],
        walk["steps"],
        walk["initial"],
        walk["sample_dt"],
        fps=fps,
        speed=speed,
        from_=from_,
        to=to,
        width=width,
        height=height,
        horizontal=horizontal,
        still=still,
    )
    if path is not None:
        out = Path(path)
        out.write_bytes(data)
        return out
    try:
        from IPython.display import Image
    except ImportError:
        return data
    return Image(data=data, format="png" if still is not None else "gif")
