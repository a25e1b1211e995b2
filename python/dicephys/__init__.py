"""dicephys from Python: the same engines, the same library and the same numbers as the CLI.

Every function here calls the Rust library the ``dicephys`` program is built on, with the
library's own types; the same seed gives the same counts as the command line. What comes back
is the JSON document the command line prints with ``--json`` (docs/json.md names its fields),
as an object whose fields read as attributes, plus NumPy arrays where a run has rows.

Runs release the GIL and can be stopped with Ctrl-C (``KeyboardInterrupt``, nothing
half-written). Progress goes to ``progress``: a callable ``progress(done, total)``, ``True``
for a tqdm bar (when tqdm is installed), ``False`` for none; the default ``None`` shows a tqdm
bar when tqdm is installed and standard error is a terminal or a notebook.

    >>> import dicephys
    >>> r = dicephys.roll("140x24x20", rolls=2000, seed=1)
    >>> r.counts
    {'breadth': 657, 'length': 0, 'unknown': 0, 'width': 1343}
"""

from __future__ import annotations

import csv
import io
import json as _json
import os
import sys
import tempfile
from typing import Any, Callable, Dict, Iterable, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

from . import _native

__all__ = [
    "Design",
    "Document",
    "Fit",
    "Roll",
    "Sweep",
    "Trace",
    "TracedThrow",
    "Value",
    "compare",
    "design",
    "fair",
    "fit",
    "paper",
    "per_roll_dtype",
    "predict",
    "recover",
    "roll",
    "study",
    "theory",
    "trace",
    "trace_dtype",
    "__version__",
]

__version__: str = _native.version()

PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[None, bool, Callable[[float, float], Any]]
RangeArg = Union[None, float, Tuple[float, float]]

# The library's defaults, as the command line's.
DEFAULT_MAX_STEPS: int = _native.DEFAULT_MAX_STEPS
DEFAULT_MARGIN: float = _native.DEFAULT_MARGIN
DEFAULT_SEED: int = _native.DEFAULT_SEED
DEFAULT_DT: float = _native.DEFAULT_DT
DEFAULT_FRICTION: float = _native.DEFAULT_FRICTION
DEFAULT_RESTITUTION: float = _native.DEFAULT_RESTITUTION
DEFAULT_ROLLS: int = _native.DEFAULT_ROLLS
DEFAULT_SPIN_SCALE: float = _native.DEFAULT_SPIN_SCALE
DEFAULT_POINTS: int = _native.DEFAULT_POINTS
DEFAULT_POINT_ROLLS: int = _native.DEFAULT_POINT_ROLLS
DEFAULT_REPEATS: int = _native.DEFAULT_REPEATS
DEFAULT_DRAWS: int = _native.DEFAULT_DRAWS
DEFAULT_PREDICT_ROLLS: int = _native.DEFAULT_PREDICT_ROLLS
DEFAULT_ENGINES: Tuple[str, ...] = tuple(_native.DEFAULT_ENGINES)
DEFAULT_DESIGN_ROLLS: int = _native.DEFAULT_DESIGN_ROLLS
DEFAULT_DESIGN_POINTS: int = _native.DEFAULT_DESIGN_POINTS
DEFAULT_CHECK_ROLLS: int = _native.DEFAULT_CHECK_ROLLS
DEFAULT_FACETS_ROLLS: int = _native.DEFAULT_FACETS_ROLLS
DEFAULT_FACETS_ROUNDS: int = _native.DEFAULT_FACETS_ROUNDS


class Value(NamedTuple):
    """A number with its one-standard-error uncertainty."""

    value: float
    error: float


class Document:
    """A JSON document the library wrote (the ``--json`` output of the matching command).

    Its top-level fields read as attributes (``doc.rolls``) or items (``doc["rolls"]``);
    ``doc.data`` is the whole parsed document and ``doc.json()`` its text.
    """

    def __init__(self, text: str) -> None:
        self._text = text
        self.data: Dict[str, Any] = _json.loads(text)

    def json(self) -> str:
        """The document's text, as the command line prints it."""
        return self._text

    def __getitem__(self, key: str) -> Any:
        return self.data[key]

    def __getattr__(self, key: str) -> Any:
        try:
            return self.__dict__["data"][key]
        except KeyError:
            raise AttributeError(key) from None

    def __contains__(self, key: str) -> bool:
        return key in self.data

    def keys(self) -> Iterable[str]:
        """The document's top-level fields."""
        return self.data.keys()

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self.data))

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}=…" for k in list(self.data)[:6])
        return f"{type(self).__name__}({shown})"


def per_roll_dtype() -> Any:
    """The NumPy dtype of a roll's per-roll array: the ``--per-roll`` CSV's columns.

    ``outcome`` is the side vertical (empty for a failed roll), ``face`` the number up
    (0 where the CSV leaves it empty: not settled on a side).
    """
    import numpy as np

    return np.dtype(
        [
            ("index", np.uint64),
            ("drop_height_m", np.float64),
            ("velocity_m_s", np.float64),
            ("spin_rad_s", np.float64),
            ("status", "U16"),
            ("outcome", "U8"),
            ("steps", np.uint64),
            ("sim_time_s", np.float64),
            ("energy_gain", np.uint8),
            ("dip_steps", np.uint64),
            ("longest_dip_steps", np.uint64),
            ("penetration_m", np.float64),
            ("face", np.uint8),
        ]
    )


def _rows(csv_bytes: bytes) -> Any:
    """The per-roll CSV as a NumPy structured array (``per_roll_dtype``)."""
    import numpy as np

    dtype = per_roll_dtype()
    reader = csv.reader(io.StringIO(csv_bytes.decode("utf-8")))
    header = next(reader)
    if tuple(header) != dtype.names:
        raise RuntimeError(f"per-roll columns {header} are not {dtype.names}")
    kinds = [dtype.fields[n][0].kind for n in dtype.names]
    rows = []
    for row in reader:
        rows.append(
            tuple(
                (int(v) if v else 0) if k in "ui" else float(v) if k == "f" else v
                for v, k in zip(row, kinds)
            )
        )
    return np.array(rows, dtype=dtype)


class Roll(Document):
    """A roll's result: ``dicephys roll --json``'s document (docs/json.md, "roll"), or
    ``fair --json``'s (its ``fairness`` beside the run's).

    ``counts`` (which side ended vertical), ``faces`` (the number up), ``ratio`` with its
    error; ``summary()`` is the text the command line prints, ``face_table()`` the faces as
    NumPy columns (``pandas.DataFrame(r.face_table())`` for a frame); ``result`` is the run's
    document (``roll --json``'s, or ``fair``'s ``summary``). With ``per_roll=True``,
    ``per_roll`` is a NumPy structured array of every throw (the ``--per-roll`` CSV's columns,
    ``per_roll_dtype()``) and ``per_roll_csv`` its bytes.
    """

    def __init__(self, text: str, human: str, csv_bytes: Optional[bytes]) -> None:
        super().__init__(text)
        self.result: Dict[str, Any] = self.data.get("summary", self.data)
        self._human = human
        self.per_roll_csv: Optional[bytes] = csv_bytes
        self.per_roll: Any = _rows(csv_bytes) if csv_bytes is not None else None

    def summary(self) -> str:
        """What ``dicephys roll`` (or ``fair``) prints for this run, as text."""
        return self._human

    def __repr__(self) -> str:
        r = self.result
        shape = r.get("spec", {}).get("scene", {}).get("shape")
        die = shape["name"] if shape else "x".join(f"{v:g}" for v in r.get("block_mm", []))
        engine = r.get("spec", {}).get("engine", "?")
        head = f"{type(self).__name__}({die}, {engine}, {r.get('rolls', 0):,} rolls"
        if "summary" not in self.data and "fairness" in self.data:
            head = f"{type(self).__name__}(counted, {self.data['fairness']['n']:,} throws"
        faces = self.faces
        if 0 < len(faces) <= 12:
            head += ": faces " + " ".join(f"{k}:{v}" for k, v in faces.items())
        elif faces:
            head += f": {len(faces)} faces"
        if "fairness" in self.data:
            f = self.data["fairness"]
            word = str(f["verdict"]).split(":")[0]
            head += f"; {word} (χ² {f['chi2']:.1f} on {f['dof']}, p {f['p_value']:.2g})"
        elif shape is None and r.get("ratio") is not None:
            head += f"; ratio {r['ratio']:.4f} ± {r['ratio_err']:.4f}"
        return head + ")"

    def face_table(self) -> Dict[str, Any]:
        """The faces as NumPy columns: ``label``, ``count``, ``p`` and ``err`` (1σ), and for
        ``fair`` ``null`` and ``z``, one row per face in the die's order."""
        import numpy as np

        if "fairness" in self.data:
            rows = self.data["fairness"]["faces"]
            cols: Dict[str, Any] = {
                "label": np.array([str(f.get("label", f.get("number"))) for f in rows]),
                "count": np.array([f["count"] for f in rows], dtype=np.int64),
                "p": np.array([f["p"] for f in rows], dtype=np.float64),
                "err": np.array([f["err"] for f in rows], dtype=np.float64),
                "null": np.array([f["null"] for f in rows], dtype=np.float64),
                "z": np.array([np.nan if f["z"] is None else f["z"] for f in rows], dtype=np.float64),
            }
            return cols
        faces = self.faces
        n = sum(faces.values())
        count = np.array(list(faces.values()), dtype=np.int64)
        p = count / n if n else np.full(len(count), np.nan)
        return {
            "label": np.array(list(faces.keys())),
            "count": count,
            "p": p,
            "err": np.sqrt(p * (1 - p) / n) if n else np.full(len(count), np.nan),
        }

    @property
    def counts(self) -> Dict[str, int]:
        """Rolls by the side that ended vertical (length, breadth, width, unknown)."""
        return dict(self.result["counts"])

    @property
    def faces(self) -> Dict[str, int]:
        """Rolls by the number up, ``"1"``…``"6"`` (in 2D the four sides' numbers); for
        ``fair(counts=…)`` the counts judged, by label."""
        if "summary" not in self.data and "fairness" in self.data:
            return {str(f["direction"]): int(f["count"]) for f in self.data["fairness"]["faces"]}
        return dict(self.result.get("faces", {}))

    @property
    def ratio(self) -> Value:
        """N(breadth vertical) / N(width vertical), the paper's ratio, with its error."""
        return Value(self.result["ratio"], self.result["ratio_err"])

    @property
    def theory_ratio(self) -> float:
        """The paper's 2D theory of the ratio for this block (its eq. MasterEqu)."""
        return float(self.result["theory_ratio"])


class Sweep(Document):
    """``fair(vary=…)``'s result: ``dicephys fair --vary --json``'s document (docs/json.md,
    "fair --vary"): ``vary`` (the feature), ``null``, ``spec`` (the run at each value) and
    ``points``, each value's ``value`` (mm) and ``fairness``. ``summary()`` is the table the
    command line prints, ``table()`` the points as NumPy columns."""

    def __init__(self, text: str, human: str) -> None:
        super().__init__(text)
        self._human = human

    def summary(self) -> str:
        """What ``dicephys fair --vary`` prints for this sweep, as text."""
        return self._human

    def table(self) -> Dict[str, Any]:
        """``value`` (mm, one a point), ``label`` (one a face), and ``p``, ``err`` and ``z``
        (a row a point, a column a face, in the faces' order), and each point's χ² ``p_value``."""
        import numpy as np

        points = self.data["points"]
        faces = [f["faces"] for f in (p["fairness"] for p in points)]

        def col(key: str) -> Any:
            return np.array([[np.nan if x[key] is None else x[key] for x in row] for row in faces], dtype=np.float64)

        return {
            "value": np.array([p["value"] for p in points], dtype=np.float64),
            "label": np.array([str(f.get("label", f["number"])) for f in faces[0]] if faces else []),
            "p": col("p"),
            "err": col("err"),
            "z": col("z"),
            "p_value": np.array([p["fairness"]["p_value"] for p in points], dtype=np.float64),
        }

    def __repr__(self) -> str:
        points = self.data.get("points", [])
        values = [p["value"] for p in points]
        span = f"{min(values):g}…{max(values):g} mm" if values else "no values"
        return f"Sweep({self.data.get('vary')} {span}, {len(points)} values; null {self.data.get('null')})"


class Fit(Document):
    """A fit's result: ``dicephys fit --json``'s document (docs/json.md, "fit"), written with
    its report and figures into ``out``."""

    def __init__(self, text: str, out: str) -> None:
        super().__init__(text)
        self.out: str = out

    @property
    def path(self) -> str:
        """The fit's ``fit.json``, which ``predict`` and ``dicephys predict --fit`` read."""
        return os.path.join(self.out, "fit.json")

    def summary(self) -> str:
        """The fit's report (``report.md``, what ``dicephys fit`` prints), as text."""
        with open(os.path.join(self.out, "report.md"), encoding="utf-8") as f:
            return f.read()

    @property
    def discrepancy(self) -> Optional[Dict[str, Any]]:
        """How far the fit's rows, each predicted without itself, miss beyond their errors,
        outcome by outcome (where ``asked``: a line on the log-odds, ``shift`` and ``slope``
        about ``centre``, with a spread ``tau`` about it), along which every ``predict`` from
        the fit is moved (its ``fit_value`` the fit's own) and by which it is widened (its
        ``err_model``); ``None`` for a fit of fewer than three rows (docs/json.md, fit.json's
        ``discrepancy``)."""
        d = self.data.get("discrepancy")
        return dict(d) if d is not None else None

    def __repr__(self) -> str:
        e = self.data.get("estimate", {})
        shown = []
        for p in e.get("params", []):
            lo, hi = (p.get("one_sigma") or [None, None])[:2]
            value = f"{p['name']} {p['value']:.4g}"
            if lo is not None and hi is not None:
                value += f" (1σ {lo:.4g}–{hi:.4g})"
            if p.get("identified") == "no":
                value += " unidentified"
            shown.append(value)
        fit = ""
        if e.get("p_value") is not None:
            fit = f"; χ² {e['chi2']:.1f} on {e['dof']}, p {e['p_value']:.2g}"
        return f"Fit({', '.join(shown)}{fit}; out={self.out!r})"


def _progress(progress: Progress, what: str) -> Tuple[Optional[Callable[[float, float], Any]], Callable[[], None]]:
    """The callback a run reports to, and what closes it."""
    if callable(progress):
        return progress, lambda: None
    if progress is not None and not isinstance(progress, bool):
        # As the command line refuses what it does not know (reliability round 5, class I).
        raise ValueError(
            f"progress={progress!r}: give None (a bar on a terminal), True, False or a "
            "callable(done, total)"
        )
    if progress is False:
        return None, lambda: None
    try:
        from tqdm.auto import tqdm  # type: ignore[import-untyped,import-not-found,unused-ignore]
    except ImportError:
        return None, lambda: None
    if progress is None and not (sys.stderr.isatty() or "ipykernel" in sys.modules):
        return None, lambda: None
    bar = tqdm(total=0, desc=what, unit="roll" if what in ("roll", "fair") else "")

    def tell(done: float, total: float) -> None:
        # Whole counts (rolls, cells): "2000/20000", not "2000.0/20000.0".
        bar.total = int(round(total))
        bar.n = int(round(min(done, total)))
        bar.refresh()

    return tell, bar.close


def _pair(name: str, x: RangeArg) -> Any:
    if x is None or isinstance(x, (int, float)):
        return x
    try:
        lo, hi = x
        return (float(lo), float(hi))
    except (TypeError, ValueError):
        raise ValueError(f"{name}={x!r}: give a number or (low, high)") from None


def _triple(name: str, x: Optional[Sequence[float]], n: int) -> Optional[List[float]]:
    if x is None:
        return None
    # A string is a sequence of characters: '0,0,-1' would be read one character at a time.
    if isinstance(x, (str, bytes)):
        raise ValueError(f"{name}={x!r}: give {n} numbers of mm as a tuple, not a string")
    try:
        values = [float(v) for v in x]
    except (TypeError, ValueError):
        raise ValueError(f"{name}={x!r}: give {n} numbers of mm") from None
    if len(values) != n:
        raise ValueError(f"{name}={tuple(x)}: give {n} numbers of mm")
    return values


def _names(name: str, x: Union[str, Sequence[str]]) -> List[str]:
    """Parameter names: a sequence of them, or one string as the CLI spells it ("e,mu")."""
    if isinstance(x, str):
        return [p.strip() for p in x.split(",") if p.strip()]
    if not all(isinstance(p, str) for p in x):
        raise ValueError(f"{name}={x!r}: give parameter names, e.g. ('e', 'mu')")
    return list(x)


def _contact(x: Optional[Sequence[float]]) -> Optional[Tuple[float, float]]:
    if x is None:
        return None
    if isinstance(x, (str, bytes)):
        raise ValueError(f"contact={x!r}: give (e, mu) as two numbers, not a string")
    try:
        e, mu = x
        return (float(e), float(mu))
    except (TypeError, ValueError):
        raise ValueError(f"contact={x!r}: give (e, mu) as two numbers") from None


def roll(
    block: Optional[str] = None,
    *,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    rolls: Optional[int] = None,
    seed: int = DEFAULT_SEED,
    mode: str = "3d",
    engine: str = "bullet",
    dt: float = DEFAULT_DT,
    restitution: float = DEFAULT_RESTITUTION,
    friction: float = DEFAULT_FRICTION,
    density: Optional[float] = None,
    throw: Optional[str] = None,
    kappa: Optional[float] = None,
    source: str = "keyed",
    velocity: RangeArg = None,
    spin: RangeArg = None,
    drop_height: RangeArg = None,
    preset: str = "dicephys281",
    floor: str = "box",
    floor_thickness: Optional[float] = None,
    linear_damping: float = 0.0,
    angular_damping: float = 0.0,
    rolling_resistance: Optional[float] = None,
    bounce_threshold: float = 0.0,
    contact_time: float = 0.0,
    static_ratio: float = 1.0,
    sleep: bool = True,
    settle: Optional[str] = None,
    flight: str = "fast",
    faithful: bool = False,
    max_steps: Optional[int] = None,
    margin: float = DEFAULT_MARGIN,
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    die: Optional[PathLike] = None,
    layout: Optional[str] = None,
    threads: int = 0,
    per_roll: bool = False,
    precision: Optional[float] = None,
    progress: Progress = None,
) -> Roll:
    """Throws one block many times on one engine: ``dicephys roll``.

    block: LENGTHxBREADTHxWIDTH in mm, the paper's order ("140x24x20").
    shape: a die of any shape in place of ``block``, as ``--shape``: "d4", "d6", "d8",
        "d10", "d12", "d20", "coin:D,H", "prism:N,D,L" (thrown in a tumble); size: its
        size in mm instead of the standard one.  A mesh die is ``die="my.stl"`` (OBJ or
        STL, mm, times ``scale``).  No block, shape or die: a 16 mm d6.
    rolls: throws (default 10,000; with ``precision``, the most it may take, 10,000,000).
    seed: the keyed throws' seed; the same seed gives the same counts on any thread count.
    mode: "3d" or "2d" (DicePhys's plane-locked block).
    engine: "bullet", "rapier", "rapier-locked" or "moreau" (the arbiter).
    dt: the fixed time step, s.  restitution, friction: the die's e and μ (the floor's are 1).
    density: kg/m³ (default 800, or the ``die`` file's).
    throw: "paper" (the default), "tumble", "hand" (with ``kappa``), "rest" or "toss" (a
        hand's toss: the tumble's directions, its magnitudes drawn with scales).
    kappa: a hand's throw's concentration κ (alone, it asks for ``throw="hand"``).
    source: "keyed" (each throw from (seed, index)) or "dicephys" (DicePhys's rand()).
    velocity, spin, drop_height: the throw's ranges, one number or (low, high)
        (m/s, rad/s, m; defaults the paper's).
    preset, floor, floor_thickness, linear_damping, angular_damping, sleep: the scene
        (as ``dicephys roll --help`` says).
    rolling_resistance: mm, the lever arm of the floor's push against rolling and turning in
        place (so that a coin rolling on its rim stops); Bullet, and Rapier in 3D; None:
        0.05 for a coin (a hard table), else 0.
    bounce_threshold: m/s, impacts slower than this do not bounce (0: every one does);
        contact_time: ms, a soft table whose flat landing lasts this long and leaves at
        ``restitution`` times its speed (0: the rigid contact; else at least two steps of
        ``dt``); static_ratio: static over sliding friction (a contact point not sliding
        holds up to this times ``friction``; 1: one friction). All three Bullet only.
    settle: None (the exact early stop where it is audited exact), "certificate" or
        "dicephys".  flight: "fast" or "stepped".  faithful: DicePhys as the paper ran it.
    com: the centre of mass (x, y, z) in mm from the geometric centre; pips: (diameter,
        depth) in mm; edge_radius: mm; shell: a printed die's (wall mm, infill fraction);
        die: a die file (TOML) — a die as it is made.
    layout: "right" or "left": how the numbers sit on the faces (default: the ``die``
        file's layout or face map, else "right").
    threads: worker threads (0: one per core).
    per_roll: also return every throw as a NumPy structured array (``Roll.per_roll``).
    precision: roll until the ratio's relative 2σ error is at most this fraction
        (0.02 is 2 %), tested every 1,000 rolls.
    progress: see the module's help.
    """
    return _roll(
        block, "roll", progress, None, precision,
        shape=shape, size=size, scale=scale, rolls=rolls, seed=seed, mode=mode, engine=engine,
        dt=dt, restitution=restitution, friction=friction, density=density, preset=preset,
        floor=floor, floor_thickness=floor_thickness, linear_damping=linear_damping,
        angular_damping=angular_damping, rolling_resistance=rolling_resistance, sleep=sleep,
        bounce_threshold=bounce_threshold, contact_time=contact_time, static_ratio=static_ratio,
        throw=throw, kappa=kappa, source=source, velocity=velocity, spin=spin,
        drop_height=drop_height, settle=settle, flight=flight, faithful=faithful,
        max_steps=max_steps, margin=margin, com=com, pips=pips, edge_radius=edge_radius,
        shell=shell, die=die,
        layout=layout, threads=threads, per_roll=per_roll,
    )


def _roll(
    block: Optional[str],
    what: str,
    progress: Progress,
    null: Optional[str],
    precision: Optional[float],
    **opts: Any,
) -> Roll:
    """``roll``'s and ``fair``'s one call into the library, the arguments converted."""
    text, human, csv_bytes = _call(block, what, progress, null, precision, **opts)
    return Roll(text, human, csv_bytes)


def _call(
    block: Optional[str],
    what: str,
    progress: Progress,
    null: Optional[str],
    precision: Optional[float],
    **opts: Any,
) -> Tuple[str, str, Optional[bytes]]:
    """The library's run for ``roll`` and ``fair``: its document, its text and its per-roll
    CSV, the arguments converted."""
    if isinstance(opts.get("rolls"), bool):
        raise ValueError(f"rolls={opts['rolls']!r}: give a number of rolls")
    for k in ("velocity", "spin", "drop_height"):
        opts[k] = _pair(k, opts.get(k))
    opts["com"] = _triple("com", opts.get("com"), 3)
    opts["pips"] = _triple("pips", opts.get("pips"), 2)
    opts["shell"] = _triple("shell", opts.get("shell"), 2)
    # A bool is an int to Python and a number to the library: size=True would be 1 mm.
    for k in ("size", "scale", "density", "edge_radius", "kappa", "dt", "restitution", "friction"):
        if isinstance(opts.get(k), bool):
            raise ValueError(f"{k}={opts[k]!r}: give a number")
    if opts.get("die") is not None:
        try:
            opts["die"] = os.fspath(opts["die"])
        except TypeError:
            raise TypeError(f"die={opts['die']!r}: give a path (a str or an os.PathLike)") from None
    tell, close = _progress(progress, what)
    try:
        text, human, csv_bytes = _native.roll(
            block, precision=precision, fair=null, progress=tell, **opts
        )
    finally:
        close()
    return text, human, None if csv_bytes is None else bytes(csv_bytes)


def fair(
    block: Optional[str] = None,
    *,
    null: str = "uniform",
    within: Optional[float] = None,
    counts: Union[None, str, Mapping[str, int], Sequence[int]] = None,
    vary: Union[None, str, Tuple[str, float, float, int]] = None,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    rolls: Optional[int] = None,
    seed: int = DEFAULT_SEED,
    mode: str = "3d",
    engine: str = "bullet",
    dt: float = DEFAULT_DT,
    restitution: float = DEFAULT_RESTITUTION,
    friction: float = DEFAULT_FRICTION,
    density: Optional[float] = None,
    throw: str = "tumble",
    kappa: Optional[float] = None,
    source: str = "keyed",
    velocity: RangeArg = None,
    spin: RangeArg = None,
    drop_height: RangeArg = None,
    preset: str = "dicephys281",
    floor: str = "box",
    floor_thickness: Optional[float] = None,
    linear_damping: float = 0.0,
    angular_damping: float = 0.0,
    rolling_resistance: Optional[float] = None,
    bounce_threshold: float = 0.0,
    contact_time: float = 0.0,
    static_ratio: float = 1.0,
    sleep: bool = True,
    settle: Optional[str] = None,
    flight: str = "fast",
    faithful: bool = False,
    max_steps: Optional[int] = None,
    margin: float = DEFAULT_MARGIN,
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    die: Optional[PathLike] = None,
    layout: Optional[str] = None,
    threads: int = 0,
    per_roll: bool = False,
    progress: Progress = None,
    precision: Optional[float] = None,
) -> Union[Roll, Sweep]:
    """Is this die fair, face by face: ``dicephys fair --json``.

    Rolls the die as ``roll`` does (the same arguments, with the same meanings; thrown in a
    tumble unless ``throw`` says otherwise) and sets each face against ``null``: "uniform"
    (each face 1/N) or "quasi-static" (also "solid-angle": released at rest, rolling without a
    bounce; 3D). The result's ``fairness`` is the fair report (each face's probability, its
    departure in σ, χ², the throws a tester needs); ``probabilities()`` the faces as arrays.

    within: roll until every face's probability is known to this 2σ, a probability (0.005:
        each face to ±0.005; the command line's ``--within 0.5``, in percentage points).
    precision: the old name of ``within`` (deprecated: in ``roll`` it is the ratio's relative
        error).
    counts: judge counts you measured instead of rolling (``fair --counts``): a mapping
        label → count (``{"1": 170, "2": 160, …}``, ``{"heads": 48, "tails": 51}``), counts in
        the faces' order (a numbered die's 1 … N; other labels in the die's own order, a
        coin's heads, tails, edge), or the
        command line's text ``"1=170,2=160,…"``; against ``null`` (uniform: 1/N over the faces
        given; quasi-static: the die ``block``, ``shape`` or ``die`` describe). Nothing is
        rolled: the arguments that say how a die is rolled are refused beside it. Returns a
        ``Roll`` whose ``fairness`` is the verdict (``faces`` the counts).
    vary: how a feature of the die biases it (``fair --vary``): ``"NAME=LO:HI:N"`` or
        ``(NAME, LO, HI, N)``, the die rolled at N values of NAME from LO to HI mm (NAME
        ``com_x``, ``com_y``, ``com_z``, ``pip_depth`` or ``edge_radius``), the same throws at
        each, each judged against ``null``. Returns a ``Sweep`` (``fair --vary --json``'s
        document: ``points``, each value's ``fairness``).
    """
    if precision is not None:
        if within is not None:
            raise ValueError("give within= (precision= is its old name), not both")
        import warnings

        warnings.warn("fair(precision=) is now fair(within=)", DeprecationWarning, stacklevel=2)
        within = precision
    if counts is not None or vary is not None:
        _refuse_beside(counts, vary, locals())
    given: Any = counts
    if isinstance(counts, Mapping):
        given = [(str(k), v) for k, v in counts.items()]
    elif isinstance(counts, Iterable) and not isinstance(counts, (str, bytes)):
        given = list(counts)
    if isinstance(vary, tuple):
        try:
            name, lo, hi, n = vary
            vary = f"{name}={float(lo)!r}:{float(hi)!r}:{int(n)}"
        except (TypeError, ValueError):
            raise ValueError(f"vary={vary!r}: give 'NAME=LO:HI:N' or (NAME, LO, HI, N)") from None
    text, human, csv_bytes = _call(
        block, "fair", progress, null, within, counts=given, vary=vary,
        shape=shape, size=size, scale=scale, rolls=rolls, seed=seed, mode=mode, engine=engine,
        dt=dt, restitution=restitution, friction=friction, density=density, preset=preset,
        floor=floor, floor_thickness=floor_thickness, linear_damping=linear_damping,
        angular_damping=angular_damping, rolling_resistance=rolling_resistance, sleep=sleep,
        bounce_threshold=bounce_threshold, contact_time=contact_time, static_ratio=static_ratio,
        throw=throw, kappa=kappa, source=source, velocity=velocity, spin=spin,
        drop_height=drop_height, settle=settle, flight=flight, faithful=faithful,
        max_steps=max_steps, margin=margin, com=com, pips=pips, edge_radius=edge_radius,
        shell=shell, die=die,
        layout=layout, threads=threads, per_roll=per_roll,
    )
    if vary is not None:
        return Sweep(text, human)
    return Roll(text, human, csv_bytes)


# What says how a die is rolled, with each default: refused beside fair(counts=), which rolls
# nothing (the die's own arguments stay: the quasi-static null reads them), as the command
# line refuses its flags beside --counts.
_SIMULATION: Dict[str, Any] = dict(
    rolls=None, seed=DEFAULT_SEED, engine="bullet", dt=DEFAULT_DT,
    restitution=DEFAULT_RESTITUTION, friction=DEFAULT_FRICTION, throw="tumble", kappa=None,
    source="keyed", velocity=None, spin=None, drop_height=None, preset="dicephys281",
    floor="box", floor_thickness=None, linear_damping=0.0, angular_damping=0.0,
    rolling_resistance=None, bounce_threshold=0.0, contact_time=0.0, sleep=True, settle=None,
    flight="fast", faithful=False, max_steps=None, margin=DEFAULT_MARGIN, threads=0,
    per_roll=False, within=None,
)
# Refused beside fair(vary=), as beside --vary: a sweep rolls ``rolls`` at each value.
_NOT_WITH_VARY = ("within", "per_roll")


def _refuse_beside(counts: Any, vary: Any, given: Mapping[str, Any]) -> None:
    """A ValueError naming what ``fair(counts=)`` or ``fair(vary=)`` cannot be given with."""
    if counts is not None and vary is not None:
        raise ValueError("counts= and vary= cannot be used together: counts judges measured "
                         "throws, vary rolls the die at each value")
    if counts is not None:
        names = [k for k, v in _SIMULATION.items() if given[k] != v]
        why = "counts= judges measured throws and rolls nothing"
    else:
        names = [k for k in _NOT_WITH_VARY if given[k] not in (None, False)]
        why = "vary= rolls the die `rolls` times at each value"
    if names:
        shown = ", ".join(f"{k}={given[k]!r}" for k in names)
        raise ValueError(f"{'counts' if counts is not None else 'vary'}=: cannot be used with {shown} ({why})")


def theory(block: Optional[str] = None, *, tolerance: float = 0.1) -> Document:
    """The paper's closed forms for one block (``dicephys theory --block B --json``), or,
    without a block, its whole experimental table against the theory (``--table --json``).

    tolerance: the uncertainty of each measured side, mm, carried into R and the ratio.
    """
    return Document(_native.theory(block, tolerance))


def _out(out: Optional[PathLike], what: str) -> str:
    if out is None:
        return tempfile.mkdtemp(prefix=f"dicephys-{what}-")
    return os.fspath(out)


def _run_study(config: str, out: str, threads: int, progress: Progress, what: str) -> Document:
    tell, close = _progress(progress, what)
    try:
        text = _native.study(config, out, threads=threads, progress=tell, log=_log)
    finally:
        close()
    return Document(text)


def _log(line: str) -> None:
    import logging

    logging.getLogger("dicephys").info(line)


def paper(
    out: PathLike = "paper-out",
    *,
    rolls: int = DEFAULT_ROLLS,
    seed: int = DEFAULT_SEED,
    engines: Sequence[str] = DEFAULT_ENGINES,
    dt: float = DEFAULT_DT,
    max_steps: int = DEFAULT_MAX_STEPS,
    faithful: bool = False,
    threads: int = 0,
    progress: Progress = None,
) -> Document:
    """The paper end to end (``dicephys paper``): writes results.json, results.csv, report.md
    and the figures into ``out`` and returns results.json's document. Run again with the same
    arguments, it continues where it stopped."""
    config = _native.paper_config(rolls, seed, list(engines), dt, max_steps, faithful)
    return _run_study(config, os.fspath(out), threads, progress, "paper")


def study(config: Mapping[str, Any], out: PathLike, *, threads: int = 0, progress: Progress = None) -> Document:
    """Any study the command line runs (``paper``, ``crosscheck``, ``converge``,
    ``tradeoff``, ``stability``, ``fit``, ``paper --calibrated``; and ``validate``,
    ``recover``, ``predict``, ``predict_blocks``, which run only here) from its configuration as a
    Slurm plan stores it: a mapping tagged by ``"study"``, the ``config`` of the slurm.json
    that ``dicephys slurm <study> … --dir D`` writes (without ``--submit`` it submits
    nothing). Writes its files into ``out``; returns its JSON result."""
    return _run_study(_json.dumps(dict(config)), os.fspath(out), threads, progress, str(config.get("study", "study")))


def _data(data: Any) -> str:
    """The counts as the library reads them: a path, "paper", or CSV text."""
    if isinstance(data, (str, os.PathLike)):
        return os.fspath(data)
    if hasattr(data, "to_csv"):  # a pandas DataFrame
        return str(data.to_csv(index=False))
    rows = list(data)
    if not rows:
        raise ValueError("data=[]: no rows")
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _fit_config(
    data: Any,
    free: Sequence[str],
    shared: Sequence[str],
    ranges: Optional[Mapping[str, Tuple[float, float]]],
    restitution: float,
    friction: float,
    kappa: Union[None, str, float],
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
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    die: Optional[PathLike] = None,
    layout: Optional[str] = None,
    density: Optional[float] = None,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
) -> str:
    if kappa == "paper":
        kappa = None
    rs = [(k, float(lo), float(hi)) for k, (lo, hi) in (ranges or {}).items()]
    made = dict(
        com=_triple("com", com, 3), pips=_triple("pips", pips, 2), edge_radius=edge_radius,
        shell=_triple("shell", shell, 2),
        die=None if die is None else os.fspath(die), layout=layout, density=density,
        shape=shape, size=size, scale=scale,
    )
    return _native.fit_config(
        _data(data), _names("free", free), _names("shared", shared), rs, restitution, friction,
        None if kappa is None else float(kappa), spin_scale, engine, dt, max_steps, points,
        point_rolls, degree, max_degree, refine, common_throws, seed, made,
    )


def fit(
    data: Any,
    free: Sequence[str] = ("e", "mu"),
    *,
    shared: Sequence[str] = (),
    ranges: Optional[Mapping[str, Tuple[float, float]]] = None,
    restitution: float = DEFAULT_RESTITUTION,
    friction: float = DEFAULT_FRICTION,
    kappa: Union[None, str, float] = "paper",
    spin_scale: float = DEFAULT_SPIN_SCALE,
    engine: str = "bullet",
    dt: float = DEFAULT_DT,
    max_steps: int = DEFAULT_MAX_STEPS,
    points: int = DEFAULT_POINTS,
    point_rolls: int = DEFAULT_POINT_ROLLS,
    degree: Optional[int] = None,
    max_degree: Optional[int] = None,
    refine: bool = True,
    common_throws: bool = False,
    seed: int = DEFAULT_SEED,
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    die: Optional[PathLike] = None,
    layout: Optional[str] = None,
    density: Optional[float] = None,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    out: Optional[PathLike] = None,
    threads: int = 0,
    progress: Progress = None,
) -> Fit:
    """Calibrates e, μ and the throw to measured counts: ``dicephys fit``.

    data: the counts — a CSV path (docs/guide.md, "Calibrating"), "paper" (the paper's 19
        rows), a pandas DataFrame or a list of dicts with the CSV's columns.
    free: the free parameters, among "e", "mu", "rolling" (the contact's rolling resistance,
        mm; Bullet and Rapier), "kappa", "spin", "height", "speed" (the last three factors on the
        throw's spin, launch height and launch speed); for a die,
        "com_x", "com_y", "com_z" (its centre of mass, mm), "pip_depth" (mm) and "infill" (a
        printed die's infill fraction, 0 to 1, in its shell's wall or a 1 mm one).
    shared: surface parameters shared by every surface instead of one per surface.
    ranges: a free parameter's box, {"e": (0.05, 0.8)}.
    restitution, friction, kappa, spin_scale: the values where a parameter is not free
        (kappa "paper": the paper's throw, which a die of any shape takes as the tumble).
    points, point_rolls: the design (parameter points per block per pass, rolls at each).
    degree, max_degree: the surrogate's polynomial degree, first and highest (None: 3 and 4;
        2 and 2 for a die of more than six faces).
    com, pips, edge_radius, shell, die, layout, density: the die thrown, as ``roll`` takes it (one
        die for every row; a counts file with face_1 … face_6 counts its faces).
    shape, size, scale: a die of any shape, as ``roll`` takes it ("d20", "coin:24,8"; or a
        mesh ``die``): the counts are then label, surface and a face_<label> column for each
        of its faces, and it is thrown in a tumble (kappa is left out: it has no long axis).
    out: where fit.json, report.md, the figures and the simulations' cells are written
        (default: a new temporary directory, ``Fit.out``).
    """
    config = _fit_config(
        data, free, shared, ranges, restitution, friction, kappa, spin_scale, engine, dt,
        max_steps, points, point_rolls, degree, max_degree, refine, common_throws, seed,
        com=com, pips=pips, edge_radius=edge_radius, shell=shell, die=die, layout=layout,
        density=density, shape=shape, size=size, scale=scale,
    )
    where = _out(out, "fit")
    tell, close = _progress(progress, "fit")
    try:
        text = _native.fit(config, where, threads=threads, progress=tell, log=_log)
    finally:
        close()
    return Fit(text, where)


def recover(
    data: Any,
    truth: Mapping[str, float],
    *,
    repeats: int = DEFAULT_REPEATS,
    free: Optional[Sequence[str]] = None,
    shared: Sequence[str] = (),
    ranges: Optional[Mapping[str, Tuple[float, float]]] = None,
    restitution: float = DEFAULT_RESTITUTION,
    friction: float = DEFAULT_FRICTION,
    kappa: Union[None, str, float] = "paper",
    spin_scale: float = DEFAULT_SPIN_SCALE,
    engine: str = "bullet",
    dt: float = DEFAULT_DT,
    max_steps: int = DEFAULT_MAX_STEPS,
    points: int = DEFAULT_POINTS,
    point_rolls: int = DEFAULT_POINT_ROLLS,
    degree: Optional[int] = None,
    max_degree: Optional[int] = None,
    refine: bool = True,
    common_throws: bool = False,
    seed: int = DEFAULT_SEED,
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    die: Optional[PathLike] = None,
    layout: Optional[str] = None,
    density: Optional[float] = None,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    out: Optional[PathLike] = None,
    threads: int = 0,
    progress: Progress = None,
) -> Document:
    """Checks that a fit recovers known values: ``dicephys fit --recover``.

    Counts of ``data``'s rows (the same blocks and numbers of throws) are simulated at
    ``truth`` ({"e": 0.5, "mu": 0.3}: a value for every free parameter) and fitted back,
    ``repeats`` times; the result says how often the 2σ region held the truth. ``free``
    defaults to the parameters ``truth`` names; the other arguments are ``fit``'s.
    """
    free = _names("free", free) if free is not None else list(truth)
    config = _fit_config(
        data, free, shared, ranges, restitution, friction, kappa, spin_scale, engine, dt,
        max_steps, points, point_rolls, degree, max_degree, refine, common_throws, seed,
        com=com, pips=pips, edge_radius=edge_radius, shell=shell, die=die, layout=layout,
        density=density, shape=shape, size=size, scale=scale,
    )
    where = _out(out, "recover")
    tell, close = _progress(progress, "recover")
    try:
        text = _native.recover(
            config, [(k, float(v)) for k, v in truth.items()], repeats, where,
            threads=threads, progress=tell, log=_log,
        )
    finally:
        close()
    return Document(text)


def compare(first: Union[Fit, PathLike], second: Union[Fit, PathLike]) -> Document:
    """Two fits of the same counts by different models (``free``), set side by side by how
    well each predicts the rows it did not see: ``dicephys compare --json`` (docs/json.md,
    "compare"). ``doc.decision["outcome"]`` is ``richer``, ``simpler`` or ``unresolved``.

    first, second: each a ``Fit``, or the path of a fit's fit.json (a fit of three rows or
    more: its rows are scored by fits without them).
    """
    paths = [f.path if isinstance(f, Fit) else os.fspath(f) for f in (first, second)]
    texts = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            texts.append(f.read())
    return Document(_native.compare(texts[0], texts[1], (paths[0], paths[1])))


def _other_die(
    shape: Optional[str],
    die: Optional[PathLike],
    size: Optional[float],
    scale: Optional[float],
    com: Optional[Sequence[float]],
    density: Optional[float],
) -> Optional[Dict[str, Any]]:
    made = dict(
        shape=shape, die=None if die is None else os.fspath(die), size=size, scale=scale,
        com=_triple("com", com, 3), density=density,
    )
    given = {k: v for k, v in made.items() if v is not None}
    return given or None


def predict(
    fit: Union[Fit, PathLike],
    block: Optional[str] = None,
    *,
    mode: str = "3d",
    surface: Optional[str] = None,
    thrower: Optional[str] = None,
    draws: int = DEFAULT_DRAWS,
    rolls: int = DEFAULT_PREDICT_ROLLS,
    seed: int = DEFAULT_SEED,
    threads: int = 0,
    progress: Progress = None,
    contact: Optional[Tuple[float, float]] = None,
    shape: Optional[str] = None,
    die: Optional[PathLike] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    com: Optional[Sequence[float]] = None,
    density: Optional[float] = None,
    counts: Any = None,
    discrepancy: str = "auto",
) -> Document:
    """A block the fit did not see, simulated at the fit's posterior draws:
    ``dicephys predict --json`` (docs/json.md, "predict").

    fit: a ``Fit``, or the path of a fit's fit.json.
    block: the block, "140x24x20" (a fit of a die of any shape predicts that die: None).
    surface, thrower: whose fitted values to use, when the fit has several.
    contact: another surface's (e, μ), where the fit held them fixed.
    shape, die, size, scale, com, density: another die than the fit's, as ``roll`` takes it,
        thrown by the same hand on the same table (a block from a fit of a die of any shape
        is another die too): ``predict --shape``/``--die``.
    counts: counts of the die predicted (a CSV file or CSV text in ``fit``'s format): the
        prediction is scored against each row beside the default scene and the quasi-static
        theory (``doc.tests``; docs/json.md, "Proper scores").
    discrepancy: the fit's discrepancy applied where it improved the fit's held-out log score
        ("auto"), always ("on") or never ("off"): ``predict --discrepancy``.
    """
    path = fit.path if isinstance(fit, Fit) else os.fspath(fit)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    tell, close = _progress(progress, "predict")
    try:
        out = _native.predict(
            text, block, mode=mode, surface=surface, thrower=thrower, draws=draws,
            rolls=rolls, seed=seed, threads=threads, progress=tell,
            contact=_contact(contact), die=_other_die(shape, die, size, scale, com, density),
            counts=None if counts is None else _data(counts), discrepancy=discrepancy,
        )
    finally:
        close()
    return Document(out)


class Design(Document):
    """``design``'s result: ``dicephys design --json``'s document (docs/json.md, "design
    --json"): ``value`` and ``interval`` (mm), ``outcomes``, ``check`` (the design rolled at a
    fresh seed), ``quasi_static``, ``reachable``, ``verdict``; ``config.named_target`` and
    ``config.calibration`` where a named target or a fit was given. A design of a die's facets
    (``free="facets"``, "design --free facets --json") has ``rounds``, the mesh
    (``vertices``, ``triangles``, ``faces``), ``check`` and ``start_check`` (and ``by_class``
    for 2d6) in place of ``value`` and ``interval``. ``summary()`` is the text the command line
    prints."""

    def __init__(self, text: str, human: str) -> None:
        super().__init__(text)
        self._human = human

    def summary(self) -> str:
        """What ``dicephys design`` prints for this design, as text."""
        return self._human

    def __repr__(self) -> str:
        d = self.data
        if "interval" not in d:
            return f"Design(facets moved up to {d['largest_move']:.3f} mm; {d['verdict']})"
        lo, hi = d["interval"]
        what = d["config"]["what"]
        return f"Design({what} = {d['value']:.3f} mm (95 %: {lo:.3f} to {hi:.3f}); {d['verdict']})"


def design(
    block: Optional[str] = None,
    *,
    free: str,
    range: Tuple[float, float],
    target: Union[str, Mapping[str, float]],
    points: Optional[int] = None,
    check_rolls: int = DEFAULT_CHECK_ROLLS,
    rolls: Optional[int] = None,
    rounds: Optional[int] = None,
    fit: Union[None, Fit, PathLike] = None,
    surface: Optional[str] = None,
    thrower: Optional[str] = None,
    out: Optional[PathLike] = None,
    threads: int = 0,
    progress: Progress = None,
    **options: Any,
) -> Design:
    """Design a die for its throws: ``dicephys design --json``.

    The value of one feature of the die that gives ``target``'s probabilities thrown, with its
    95 % interval, checked by rolling it ``check_rolls`` times at a fresh seed, the same
    design's quasi-static shares beside (docs/guide.md, "Design a die for its throws").

    block: the die as ``roll`` takes it, with ``roll``'s options by name in ``options``
        (``shape``, ``die``, ``com``, ``seed``, ``engine``, ``throw`` …; thrown in a tumble
        unless ``throw`` says otherwise).
    free: the feature: ``thickness`` (a coin's), ``length`` (a block's or a prism's),
        ``breadth``, ``width`` (a block's), ``com_x``, ``com_y``,
        ``com_z``, ``pip_depth`` or ``edge_radius``; mm. Or ``facets``: a convex die's shape
        (``die=`` a die file, or a named polyhedron), each facet moved and tilted within
        ``range`` of its start; the result then has no ``value`` but the design's mesh
        (``vertices``, ``triangles``, ``faces``) and the rounds of throws that made it.
    range: its (LO, HI), mm, fixed before the search.
    target: ``"LABEL=P,…"`` or a mapping label → probability, summing to 1 (``rest`` gathers
        every label not named); or a named law over a die whose labels are its numbers,
        ``"2d6"`` or ``"binomial:N"``.
    rolls, points: throws at each value of a scan (default ``DEFAULT_DESIGN_ROLLS``), and
        values each of the two scans rolls (``DEFAULT_DESIGN_POINTS``); with ``facets``,
        ``rolls`` is the throws of each of ``rounds`` rounds (``DEFAULT_FACETS_ROLLS``,
        ``DEFAULT_FACETS_ROUNDS``).
    fit: design under a fit's calibration (a ``Fit`` or its fit.json's path): its e, μ,
        rolling resistance and throw at its maximum, the die this one; ``surface`` and
        ``thrower`` pick its values where it has several. The scene and throw options are then
        the fit's and refused.
    out: also write design.json, report.md, report.html and the figure design.svg, .png.
    """
    if isinstance(target, Mapping):
        target = ",".join(f"{k}={float(v)!r}" for k, v in target.items())
    lo_hi = tuple(range)
    if len(lo_hi) != 2:
        raise ValueError(f"range={range!r}: give (LO, HI), mm")
    for k in ("com", "pips", "shell"):
        options[k] = _triple(k, options.get(k), 3 if k == "com" else 2)
    for k in ("velocity", "spin", "drop_height"):
        if k in options:
            options[k] = _pair(k, options[k])
    if options.get("die") is not None:
        options["die"] = os.fspath(options["die"])
    fit_text = fit_name = None
    if fit is not None:
        fit_name = fit.path if isinstance(fit, Fit) else os.fspath(fit)
        with open(fit_name, encoding="utf-8") as f:
            fit_text = f.read()
    tell, close = _progress(progress, "design")
    try:
        text, human = _native.design(
            block, free=free, range=lo_hi, target=target, points=points,
            check_rolls=check_rolls, rolls=rolls, rounds=rounds, fit=fit_text,
            fit_name=fit_name,
            surface=surface, thrower=thrower, out=None if out is None else os.fspath(out),
            threads=threads, progress=tell, **options,
        )
    finally:
        close()
    return Design(text, human)


def trace_dtype() -> Any:
    """The NumPy dtype of a traced throw's rows: ``dicephys trace``'s CSV columns (step, time,
    the centre's position, m, its orientation as a quaternion, its velocities, m/s and rad/s,
    kinetic, potential and total energy, J, and whether the engine had put it to sleep)."""
    import numpy as np

    names = "step,time_s,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,kinetic_j,potential_j,total_j,sleeping"
    kind = {"step": np.uint64, "sleeping": np.uint8}
    return np.dtype([(n, kind.get(n, np.float64)) for n in names.split(",")])


def _trace_rows(csv_text: str) -> Any:
    """A traced throw's CSV as a NumPy structured array (``trace_dtype``)."""
    import numpy as np

    dtype = trace_dtype()
    header, _, body = csv_text.partition("\n")
    if tuple(header.split(",")) != dtype.names:
        raise RuntimeError(f"trace columns {header} are not {dtype.names}")
    values = np.loadtxt(io.StringIO(body), delimiter=",", dtype=np.float64, ndmin=2)
    rows = np.zeros(len(values), dtype=dtype)
    for k, name in enumerate(dtype.names):
        rows[name] = values[:, k]
    return rows


class TracedThrow(NamedTuple):
    """One throw of a ``Trace``: ``throw``, its index in the seed's sequence; its rows (``trace_dtype``),
    ``dicephys trace``'s CSV text, the line that says how it ended (what ``trace`` prints on
    standard error) and, where the step cap ended it, the note that says so."""

    throw: int
    rows: Any
    csv: str
    ending: str
    note: Optional[str]


class Trace:
    """``trace()``'s result: each throw's trajectory (``throws``, as ``dicephys trace`` prints
    it) and the page ``trace --html`` writes for them (``page``, self-contained HTML that plays
    the throws in 3D; ``path`` where it was written, if asked). ``rows``, ``csv`` and
    ``ending`` are the throw's when there is one. In Jupyter the page shows inline."""

    def __init__(self, throws: List[TracedThrow], page: str, path: Optional[str]) -> None:
        self.throws = throws
        self.page = page
        self.path = path

    def _one(self) -> TracedThrow:
        if len(self.throws) != 1:
            raise ValueError(f"{len(self.throws)} throws traced: take one from .throws")
        return self.throws[0]

    @property
    def rows(self) -> Any:
        """The throw's rows, a NumPy structured array (``trace_dtype()``)."""
        return self._one().rows

    @property
    def csv(self) -> str:
        """The throw's CSV, as ``dicephys trace`` prints it."""
        return self._one().csv

    @property
    def ending(self) -> str:
        """How the throw ended, the line ``dicephys trace`` prints on standard error."""
        return self._one().ending

    def _repr_html_(self) -> str:
        """The page inline (Jupyter): in an iframe of its own, so that its scripts and styles
        keep to themselves."""
        import html

        return (
            '<iframe style="width:100%;height:720px;border:0" title="dicephys trace" srcdoc="'
            + html.escape(self.page, quote=True)
            + '"></iframe>'
        )

    def __repr__(self) -> str:
        shown = "; ".join(t.ending for t in self.throws[:3])
        more = f"; … {len(self.throws) - 3} more" if len(self.throws) > 3 else ""
        return f"Trace({shown}{more})"


def trace(
    block: Optional[str] = None,
    *,
    index: Union[int, str, range] = 0,
    shape: Optional[str] = None,
    size: Optional[float] = None,
    scale: Optional[float] = None,
    die: Optional[PathLike] = None,
    seed: int = DEFAULT_SEED,
    mode: str = "3d",
    engine: str = "bullet",
    dt: float = DEFAULT_DT,
    restitution: float = DEFAULT_RESTITUTION,
    friction: float = DEFAULT_FRICTION,
    density: Optional[float] = None,
    throw: Optional[str] = None,
    kappa: Optional[float] = None,
    source: str = "keyed",
    velocity: RangeArg = None,
    spin: RangeArg = None,
    drop_height: RangeArg = None,
    preset: str = "dicephys281",
    floor: str = "box",
    floor_thickness: Optional[float] = None,
    linear_damping: float = 0.0,
    angular_damping: float = 0.0,
    rolling_resistance: Optional[float] = None,
    bounce_threshold: float = 0.0,
    contact_time: float = 0.0,
    static_ratio: float = 1.0,
    sleep: bool = True,
    com: Optional[Sequence[float]] = None,
    pips: Optional[Sequence[float]] = None,
    edge_radius: Optional[float] = None,
    shell: Optional[Sequence[float]] = None,
    max_steps: Optional[int] = None,
    flight: str = "fast",
    every: int = 1,
    html: Optional[PathLike] = None,
) -> Trace:
    """One throw's trajectory, step by step: ``dicephys trace`` (and ``--html``).

    The die, the scene and the throws as ``roll`` takes them (the same names and meanings);
    ``index`` the throw in the seed's sequence, or several: ``range(0, 10)`` or ``"0..9"``
    (both ends included, as ``--index 0..9``), at most 16.
    max_steps: the step cap (default: ``roll``'s for the die).
    flight: "fast" (in closed form where it is ballistic, as ``roll`` flies it) or "stepped".
    every: keep every Nth step's row (the first and the last always).
    html: also write the page ``trace --html`` writes here: self-contained HTML that plays the
        throws in 3D beside their heights and energies, the early stop and the outcome.

    Returns a ``Trace``: ``rows`` (a NumPy structured array of the CSV's columns,
    ``trace_dtype()``), ``csv``, ``ending``, and ``throws`` for several; ``page`` the HTML,
    which Jupyter shows inline.
    """
    if isinstance(index, bool):
        raise ValueError(f"index={index!r}: give a throw's index, a range or 'A..B'")
    if isinstance(index, range):
        if index.step != 1 or len(index) == 0:
            raise ValueError(f"index={index!r}: give a range of consecutive throws, range(A, B + 1)")
        index = f"{index.start}..{index[-1]}"
    for k, x in (("size", size), ("scale", scale), ("density", density), ("edge_radius", edge_radius),
                 ("kappa", kappa), ("dt", dt), ("restitution", restitution), ("friction", friction)):
        if isinstance(x, bool):
            raise ValueError(f"{k}={x!r}: give a number")
    throws, page = _native.trace(
        block, index=str(index), shape=shape, size=size, scale=scale,
        die=None if die is None else os.fspath(die), seed=seed, mode=mode, engine=engine, dt=dt,
        restitution=restitution, friction=friction, density=density, throw=throw, kappa=kappa,
        source=source, velocity=_pair("velocity", velocity), spin=_pair("spin", spin),
        drop_height=_pair("drop_height", drop_height), preset=preset, floor=floor,
        floor_thickness=floor_thickness, linear_damping=linear_damping,
        angular_damping=angular_damping, rolling_resistance=rolling_resistance, sleep=sleep,
        bounce_threshold=bounce_threshold, contact_time=contact_time, static_ratio=static_ratio,
        com=_triple("com", com, 3), pips=_triple("pips", pips, 2), edge_radius=edge_radius,
        shell=_triple("shell", shell, 2), max_steps=max_steps, flight=flight, every=every,
        html=None if html is None else os.fspath(html),
    )
    return Trace(
        [TracedThrow(i, _trace_rows(text), text, ending, note) for i, text, ending, note in throws],
        page,
        None if html is None else os.fspath(html),
    )
