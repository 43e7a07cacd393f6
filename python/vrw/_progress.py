"""The ``progress`` keyword of the long jobs (``sweep``, ``map``, ``orbit``, ``basin``, ``vrw.grid``).

``progress`` is ``None`` (silent, the default), a callable ``progress(done, total)`` (called on the calling
thread as points finish, at most about twenty times a second, last with ``done == total`` when the job ends
whole; an exception it raises stops the job like Ctrl-C), or ``True``: a ``tqdm`` progress bar (``tqdm.auto``,
so a widget in a notebook), which needs ``pip install tqdm``.
"""

from typing import Any, Callable, Dict, Optional

Callback = Callable[[int, int], object]


def tqdm_bar(description: str) -> Callback:
    """A callback that draws a tqdm bar, made when the first report gives the total, closed at the end."""
    try:
        from tqdm.auto import tqdm
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "progress=True draws a tqdm bar: pip install tqdm (or pass a callable progress(done, total))"
        ) from e
    bar: Optional[Any] = None

    def update(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, desc=description, unit="pt")
        bar.update(done - bar.n)
        if done >= total:
            bar.close()

    return update


def resolve(options: Dict[str, Any], description: str) -> Dict[str, Any]:
    """``options`` with its ``progress`` entry made a callable (or dropped when ``None``/``False``)."""
    progress = options.get("progress")
    if progress is None or progress is False:
        return {k: v for k, v in options.items() if k != "progress"}
    if progress is True:
        return dict(options, progress=tqdm_bar(description))
    if not callable(progress):
        raise TypeError(
            f"progress must be None, True (a tqdm bar) or a callable progress(done, total), not {progress!r}"
        )
    return options
