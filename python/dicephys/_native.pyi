"""The Rust extension (PyO3) behind ``dicephys``: JSON documents in, JSON documents out.

Use the package's functions (``dicephys.roll`` …): they wrap these with objects and arrays.
"""

from typing import Any, Callable, Dict, List, Optional, Tuple

DEFAULT_MAX_STEPS: int
DEFAULT_MARGIN: float
DEFAULT_SEED: int
DEFAULT_DT: float
DEFAULT_FRICTION: float
DEFAULT_RESTITUTION: float
DEFAULT_ROLLS: int
DEFAULT_SPIN_SCALE: float
DEFAULT_POINTS: int
DEFAULT_POINT_ROLLS: int
DEFAULT_REPEATS: int
DEFAULT_DRAWS: int
DEFAULT_PREDICT_ROLLS: int
DEFAULT_ENGINES: List[str]
DEFAULT_DESIGN_ROLLS: int
DEFAULT_DESIGN_POINTS: int
DEFAULT_CHECK_ROLLS: int
DEFAULT_FACETS_ROLLS: int
DEFAULT_FACETS_ROUNDS: int

_Progress = Optional[Callable[[float, float], Any]]
_Log = Optional[Callable[[str], Any]]

def version() -> str: ...
def roll(block: Optional[str] = None, **options: Any) -> Tuple[str, str, Optional[bytes]]:
    """``dicephys.roll``'s options by name (``fair``: a null, for ``dicephys.fair``, with
    ``counts`` or ``vary`` as ``fair --counts``/``--vary``): the JSON document, the command
    line's text, the per-roll CSV."""
    ...

def trace(
    block: Optional[str] = None, **options: Any
) -> Tuple[List[Tuple[int, str, str, Optional[str]]], str]:
    """``dicephys.trace``'s options by name: each throw's (index, CSV, ending line, the cap's
    note) and the page ``trace --html`` writes."""
    ...

def theory(block: Optional[str] = ..., tolerance: float = ...) -> str: ...
def study(config: str, out: str, *, threads: int = ..., progress: _Progress = ..., log: _Log = ...) -> str: ...
def paper_config(rolls: int, seed: int, engines: List[str], dt: float, max_steps: int, faithful: bool) -> str: ...
def fit_config(
    data: str,
    free: List[str],
    shared: List[str],
    ranges: List[Tuple[str, float, float]],
    restitution: float,
    friction: float,
    kappa: Optional[float],
    spin_scale: float,
    engine: str,
    dt: float,
    max_steps: int,
    points: int,
    point_rolls: int,
    degree: Optional[int],
    max_degree: Optional[int],
    refine: bool,
    common_throws: bool,
    seed: int,
    die: Optional[Dict[str, Any]] = ...,
) -> str: ...
def fit(config: str, out: str, *, threads: int = ..., progress: _Progress = ..., log: _Log = ...) -> str: ...
def recover(
    config: str,
    truth: List[Tuple[str, float]],
    repeats: int,
    out: str,
    *,
    threads: int = ...,
    progress: _Progress = ...,
    log: _Log = ...,
) -> str: ...
def compare(first: str, second: str, names: Tuple[str, str]) -> str: ...
def predict(
    fit: str,
    block: Optional[str] = ...,
    *,
    mode: str = ...,
    surface: Optional[str] = ...,
    thrower: Optional[str] = ...,
    draws: int = ...,
    rolls: int = ...,
    seed: int = ...,
    threads: int = ...,
    progress: _Progress = ...,
    contact: Optional[Tuple[float, float]] = ...,
    die: Optional[Dict[str, Any]] = ...,
    counts: Optional[str] = ...,
    discrepancy: str = ...,
) -> str: ...
def design(block: Optional[str] = None, **options: Any) -> Tuple[str, str]:
    """``dicephys.design``'s options by name: ``design --json``'s document and the text
    ``design`` prints."""
    ...
