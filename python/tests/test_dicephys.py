"""The Python package against the command line: the same seed gives the same numbers.

The CLI is target/release/dicephys (or $DICEPHYS_BIN); every comparison is exact (counts,
per-roll bytes), so each test can fail. Sizes are small: CI runs these in a minute or two.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Any, Dict, Iterator

import numpy as np
import pytest

import dicephys

ROOT = Path(__file__).resolve().parents[2]
BIN = os.environ.get("DICEPHYS_BIN", str(ROOT / "target" / "release" / "dicephys"))


def cli(*args: str) -> dict:
    out = subprocess.run([BIN, *args], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


@pytest.mark.parametrize(
    "engine,mode",
    [("bullet", "3d"), ("bullet", "2d"), ("rapier", "3d"), ("rapier", "2d")],
)
def test_counts_equal_the_cli_for_the_same_seed(engine: str, mode: str) -> None:
    rolls = 600 if engine == "bullet" else 200
    args = ["roll", "--block", "140x24x20", "--rolls", str(rolls), "--seed", "1", "--engine", engine, "--json"]
    if mode == "2d":
        args.append("--2d")
    want = cli(*args)
    got = dicephys.roll("140x24x20", rolls=rolls, seed=1, engine=engine, mode=mode, threads=2)
    assert got.counts == want["counts"]
    assert got.faces == want["faces"]
    assert got.ratio == (want["ratio"], want["ratio_err"])
    assert got.steps_total == want["steps_total"]
    # The same document, but for the cost of this run.
    timing = {"wall_s", "cpu_s", "cpu_ms_per_roll", "threads", "checksum"}
    mine = {k: v for k, v in got.data.items() if k not in timing}
    theirs = {k: v for k, v in want.items() if k not in timing}
    assert mine == theirs


def test_a_printed_die_in_a_toss_is_the_cli_s() -> None:
    # Issue 72's candidates through Python: a printed shell and a hand's toss.
    args = ["roll", "--shape", "d8", "--shell", "1,0.2", "--throw", "toss", "--rolls", "300"]
    want = cli(*args, "--seed", "2", "--json")
    got = dicephys.roll(shape="d8", shell=(1, 0.2), throw="toss", rolls=300, seed=2)
    assert got.faces == want["faces"]
    assert got.steps_total == want["steps_total"]
    assert want["spec"]["scene"]["features"]["shell"] == {"wall": 0.001, "infill": 0.2}
    with pytest.raises(ValueError, match="shell"):
        dicephys.roll(shape="d8", shell=(1,), rolls=10)


def test_a_die_of_any_shape_is_the_cli_s(tmp_path: Path) -> None:
    want = cli("roll", "--shape", "d20", "--rolls", "2000", "--seed", "1", "--json")
    got = dicephys.roll(shape="d20", rolls=2000, seed=1)
    assert got.faces == want["faces"]
    assert len(got.faces) == 20
    assert got.result["shape"] == want["shape"]
    # Beside each face, the quasi-static theory: a d20's 1/20.
    assert all(abs(f["quasi_static"] - 0.05) < 1e-9 for f in got.result["shape"]["faces"])
    # A mesh by its path: a cube's eight corners and six quads.
    cube = tmp_path / "cube.obj"
    corners = [(x, y, z) for x in (0, 16) for y in (0, 16) for z in (0, 16)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    cube.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
        + "".join("f " + " ".join(map(str, q)) + "\n" for q in quads)
    )
    mesh = cli("roll", "--die", str(cube), "--rolls", "200", "--seed", "3", "--json")
    assert dicephys.roll(die=str(cube), rolls=200, seed=3).faces == mesh["faces"]
    assert len(mesh["faces"]) == 6
    # A thick coin with rolling resistance: the same faces, none still rolling at the cap.
    coin = ["--shape", "coin:24,12", "--rolls", "60", "--rolling-resistance", "0.05"]
    want = cli("roll", *coin, "--seed", "1", "--json")
    got = dicephys.roll(shape="coin:24,12", rolls=60, seed=1, rolling_resistance=0.05)
    assert got.faces == want["faces"] and got.result["unconverged"] == 0
    # No die at all: the CLI's 16 mm d6, in a tumble.
    d6 = dicephys.roll(rolls=100, seed=2)
    assert d6.faces == cli("roll", "--rolls", "100", "--seed", "2", "--json")["faces"]
    assert d6.result["spec"]["throws"]["style"] == "tumble"
    with pytest.raises(ValueError, match="shape"):
        dicephys.roll(shape="d7")
    # A soft table (issue 72): the CLI's counts throw for throw; too short for the step, refused.
    soft = ["--rolls", "60", "--seed", "4", "--contact-time", "5", "--restitution", "0.3"]
    want = cli("roll", *soft, "--json")
    got = dicephys.roll(rolls=60, seed=4, contact_time=5, restitution=0.3)
    assert got.faces == want["faces"]
    assert got.result["spec"]["scene"]["contact_time"] == 0.005
    with pytest.raises(ValueError, match="contact_time"):
        dicephys.roll(rolls=10, contact_time=1)


def test_the_issue_s_example() -> None:
    # docs/python.md's first line, against `dicephys roll --block 140x24x20 --rolls 2000 --seed 1`.
    want = cli("roll", "--block", "140x24x20", "--rolls", "2000", "--seed", "1", "--json")
    assert dicephys.roll(block="140x24x20", rolls=2000, seed=1).counts == want["counts"]


def test_per_roll_arrays_match_the_cli_s_csv(tmp_path: Path) -> None:
    csv = tmp_path / "rolls.csv"
    subprocess.run(
        [BIN, "roll", "--block", "16x16x16", "--throw", "tumble", "--com", "0,0,-1", "--pips", "3,1",
         "--rolls", "300", "--seed", "7", "--per-roll", str(csv)],
        check=True, capture_output=True,
    )
    got = dicephys.roll("16x16x16", throw="tumble", com=(0, 0, -1), pips=(3, 1), rolls=300, seed=7, per_roll=True)
    assert got.per_roll_csv == csv.read_bytes()
    a = got.per_roll
    assert a.dtype == dicephys.per_roll_dtype()
    assert len(a) == 300 and list(a["index"]) == list(range(300))
    settled = a["status"] == "settled"
    # Every settled throw has a face, and the faces tally to the summary's.
    assert (a["face"][settled] > 0).all()
    for face, n in got.faces.items():
        assert int((a["face"] == int(face)).sum()) == n
    assert np.isclose(a["sim_time_s"], a["steps"] * 1e-3).all()


@pytest.mark.parametrize(
    "kwargs,name",
    [
        ({"block": "140x24"}, "block"),
        ({"block": "140x24x20", "engine": "ode"}, "engine"),
        ({"block": "140x24x20", "restitution": -0.5}, "restitution"),
        ({"block": "140x24x20", "friction": float("nan")}, "friction"),
        ({"block": "140x24x20", "dt": 0.0}, "dt"),
        ({"block": "140x24x20", "throw": "hand"}, "kappa"),
        ({"block": "140x24x20", "throw": "rest", "spin": (1, 2)}, "spin"),
        ({"block": "140x24x20", "mode": "4d"}, "mode"),
        ({"block": "140x24x20", "threads": 100000}, "threads"),
        ({"block": "16x16x16", "com": (0, 0, 9)}, "com"),
        ({"block": "16x16x16", "com": (0, 0)}, "com"),
        ({"block": "140x24x20", "velocity": "fast"}, "velocity"),
        # Reliability round 5, class I: what the command line refuses, Python refuses.
        ({"block": "140x24x20", "velocity": (2, 1)}, "velocity"),
        ({"block": "140x24x20", "drop_height": (0.4, 0.2)}, "drop_height"),
        ({"block": "140x24x20", "progress": 5}, "progress"),
        ({"block": "140x24x20", "progress": "yes"}, "progress"),
        ({"block": "140x24x20", "rolls": True}, "rolls"),
        # Issue 69, item 14: a bool is no size; an empty die file is no die.
        ({"shape": "d20", "size": True}, "size=True"),
        ({"die": "/dev/null"}, "^die=/dev/null: the die file is empty"),
        # Class G: a string where numbers belong is named, not read a character at a time.
        ({"block": "16x16x16", "com": "0,0,-1"}, "com='0,0,-1'"),
        ({"block": "16x16x16", "com": ("a", 0, 0)}, "com="),
        ({"block": "140x24x20", "kappa": "bogus"}, "kappa='bogus'"),
        # The library's own checks, named by the argument (house round 4).
        ({"block": "140x24x20", "floor": "plane", "floor_thickness": 0.02}, "floor_thickness=0.02: .* give floor box"),
        # Every field a message names is typed, and named as an argument here (issue 45).
        ({"block": "140x24x20", "throw": "hand"}, "^throw=hand: needs kappa K"),
        ({"block": "140x24x20", "throw": "rest", "velocity": (1, 2)}, "throw rest releases .* leave velocity out$"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        dicephys.roll(**{"rolls": 10, **kwargs})


def test_a_refusal_names_the_argument_the_caller_gave() -> None:
    # Issue 69, item 16: fair's target is `within`, and a die that is no path names `die`.
    with pytest.raises(ValueError, match="^within=2"):
        dicephys.fair("16x16x16", rolls=10, within=2)
    with pytest.raises(TypeError, match="^die=3: give a path"):
        dicephys.roll(rolls=10, die=3)  # type: ignore[arg-type]


def test_parameter_names_and_a_contact_are_read_as_the_cli_reads_them() -> None:
    # free='mu' is one name (it used to be read as 'm', 'u'); "e,mu" two, as --free e,mu.
    assert dicephys._names("free", "mu") == ["mu"]
    assert dicephys._names("free", "e, mu") == ["e", "mu"]
    assert dicephys._names("free", ("e", "mu")) == ["e", "mu"]
    with pytest.raises(ValueError, match="free="):
        dicephys._names("free", [1, 2])  # type: ignore[list-item]
    assert dicephys._contact((0.5, 0.3)) == (0.5, 0.3)
    with pytest.raises(ValueError, match="contact='0.5,0.3'"):
        dicephys._contact("0.5,0.3")  # type: ignore[arg-type]


@pytest.fixture
def sigint_raises() -> Iterator[None]:
    # Python installs the handler that raises KeyboardInterrupt only when SIGINT is not
    # ignored at its start; a shell that starts a job in the background without job control
    # ignores it (CI launched that way rolled 5,000,000 rolls to the end). Installed here, so
    # the test does not depend on how its process was started.
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


@pytest.mark.usefixtures("sigint_raises")
def test_a_signal_stops_a_run_with_keyboard_interrupt() -> None:
    # SIGINT half a second into a run far longer: Python's own handler raises
    # KeyboardInterrupt in the caller once the run has stopped, within a second or two.
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        dicephys.roll("140x24x20", rolls=5_000_000, threads=2)
    assert time.monotonic() - start < 30
    # And the next run is whole.
    assert sum(dicephys.roll("140x24x20", rolls=100).counts.values()) == 100


def test_progress_is_called_with_done_and_total() -> None:
    seen: list = []
    dicephys.roll("140x24x20", rolls=3000, progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (3000.0, 3000.0)
    assert all(d <= t for d, t in seen)


def test_theory_is_the_cli_s() -> None:
    assert dicephys.theory("140x24x20").data == cli("theory", "--block", "140x24x20", "--json")
    table = dicephys.theory()
    assert len(table.rows) == 19


def test_fair_reports_every_face() -> None:
    want = cli("fair", "--block", "16x16x16", "--com", "0,0,-2", "--rolls", "400", "--json")
    got = dicephys.fair("16x16x16", com=(0, 0, -2), rolls=400)
    assert got.faces == want["summary"]["faces"]
    assert got.fairness["chi2"] == want["fairness"]["chi2"]


def test_a_result_reads_at_a_glance_and_as_arrays() -> None:
    # summary() is the command line's text; the repr one short line; the faces as columns.
    got = dicephys.fair("16x16x16", com=(0, 0, -2), rolls=400, seed=5)
    text = subprocess.run(
        [BIN, "fair", "--block", "16x16x16", "--com", "0,0,-2", "--rolls", "400", "--seed", "5"],
        capture_output=True, text=True, check=True,
    ).stdout
    assert got.summary() == text
    line = repr(got)
    assert "\n" not in line and len(line) < 200 and "400 rolls" in line, line
    t = got.face_table()
    assert list(t["label"]) == ["1", "2", "3", "4", "5", "6"]
    assert int(t["count"].sum()) == sum(got.faces.values())
    assert abs(t["p"].sum() - 1) < 1e-12 and (t["err"] > 0).all() and t["z"].shape == (6,)
    r = dicephys.roll("140x24x20", rolls=500, seed=1)
    assert "ratio" in repr(r) and r.face_table()["count"].sum() == sum(r.faces.values())
    d20 = dicephys.roll(shape="d20", rolls=300, seed=1)
    assert repr(d20).startswith("Roll(d20, bullet, 300 rolls: 20 faces") and "ratio" not in repr(d20)


MEASURED = {"1": 170, "2": 160, "3": 165, "4": 180, "5": 170, "6": 178}


def test_fair_counts_judges_measured_counts_as_the_cli_does() -> None:
    # Issue 74.5: fair --counts from Python, as a mapping, in the die's order, or as the text.
    text = ",".join(f"{k}={v}" for k, v in MEASURED.items())
    want = cli("fair", "--counts", text, "--json")
    for counts in (MEASURED, list(MEASURED.values()), text):
        got = dicephys.fair(counts=counts)
        assert isinstance(got, dicephys.Roll)
        assert got.data == want, counts
    assert got.summary().startswith("Is this die fair? 1023 throws counted, against uniform")
    assert got.face_table()["count"].tolist() == list(MEASURED.values())
    assert got.faces == MEASURED
    assert repr(got).startswith("Roll(counted, 1,023 throws: faces 1:170 2:160")
    # A coin's labels, against its own shape: the quasi-static null reads the die.
    coin = {"heads": 48, "tails": 51, "edge": 1}
    want = cli("fair", "--counts", "heads=48,tails=51,edge=1", "--shape", "coin:24,8",
               "--null", "quasi-static", "--json")
    assert dicephys.fair(counts=coin, shape="coin:24,8", null="quasi-static").data == want
    assert dicephys.fair(counts=[48, 51, 1], shape="coin:24,8", null="quasi-static").data == want
    # What the command line refuses beside --counts, refused here, naming it.
    for kwargs, says in [
        (dict(rolls=100), "rolls=100"),
        (dict(seed=3), "seed=3"),
        (dict(engine="rapier"), "engine='rapier'"),
        (dict(vary="com_z=0:1:2"), "counts= and vary="),
        (dict(within=0.01), "within"),
    ]:
        with pytest.raises(ValueError, match=says):
            dicephys.fair(counts=MEASURED, **kwargs)  # type: ignore[arg-type]
    for counts, says in [
        ({"1": 5}, "at least two"),
        ({"1": 5, "2": -1}, "whole numbers of throws, 0 or more"),
        ([5, 5, 5], "the die has 20 faces"),
        ("1=5,x", "LABEL=COUNT"),
        (3.5, "a mapping label → count"),
    ]:
        with pytest.raises(ValueError, match=says):
            dicephys.fair(counts=counts, shape="d20" if isinstance(counts, list) else None)  # type: ignore[arg-type]


def test_fair_vary_is_the_cli_s_sweep() -> None:
    want = cli("fair", "--block", "16x16x16", "--vary", "com_z=0:1:2", "--rolls", "200",
               "--seed", "4", "--json")
    got = dicephys.fair("16x16x16", vary="com_z=0:1:2", rolls=200, seed=4, threads=2)
    assert isinstance(got, dicephys.Sweep)
    assert got.data == want
    assert dicephys.fair("16x16x16", vary=("com_z", 0, 1, 2), rolls=200, seed=4).data == want
    table = got.table()
    assert table["value"].tolist() == [0.0, 1.0]
    assert table["p"].shape == (2, 6)
    assert table["p"][1].tolist() == [f["p"] for f in want["points"][1]["fairness"]["faces"]]
    text = subprocess.run(
        [BIN, "fair", "--block", "16x16x16", "--vary", "com_z=0:1:2", "--rolls", "200", "--seed", "4"],
        check=True, capture_output=True, text=True,
    ).stdout
    assert got.summary() == text
    for kwargs, says in [
        (dict(within=0.01), "within"),
        (dict(per_roll=True), "per_roll"),
        (dict(vary="com_q=0:1:2"), "com_q"),
        (dict(vary="com_z=1:0:2"), "LO <= HI"),
        (dict(vary="pip_depth=0:1:2"), "no pips"),
    ]:
        opts: Dict[str, Any] = dict(vary="com_z=0:1:2", rolls=10)
        opts.update(kwargs)
        with pytest.raises(ValueError, match=says):
            dicephys.fair("16x16x16", **opts)


def test_trace_is_the_cli_s_and_its_page_too(tmp_path: Path) -> None:
    # Issue 74.5: dicephys trace from Python: the CSV's rows and ending, and the page.
    args = ["trace", "--shape", "d20", "--seed", "1", "--index", "2"]
    done = subprocess.run([BIN, *args], check=True, capture_output=True, text=True)
    t = dicephys.trace(shape="d20", seed=1, index=2)
    assert t.csv == done.stdout
    assert t.ending == done.stderr.strip()
    rows = t.rows
    assert rows.dtype == dicephys.trace_dtype()
    lines = done.stdout.splitlines()
    assert len(rows) == len(lines) - 1
    last = lines[-1].split(",")
    assert rows["step"][-1] == int(last[0]) and rows["z"][-1] == float(last[4])
    assert rows["total_j"][0] > rows["total_j"][-1]
    # Every 10th step, as --every 10.
    every = subprocess.run([BIN, *args, "--every", "10"], check=True, capture_output=True, text=True)
    assert dicephys.trace(shape="d20", seed=1, index=2, every=10).csv == every.stdout
    # Several throws and their page, as trace --index 0..2 --html writes it.
    page = tmp_path / "cli.html"
    subprocess.run([BIN, "trace", "--shape", "d20", "--seed", "1", "--index", "0..2", "--html", str(page)],
                   check=True, capture_output=True)
    mine = tmp_path / "py.html"
    several = dicephys.trace(shape="d20", seed=1, index=range(0, 3), html=mine)
    assert [s.throw for s in several.throws] == [0, 1, 2]
    assert mine.read_bytes() == page.read_bytes()
    assert several.page == page.read_text(encoding="utf-8")
    assert dicephys.trace(shape="d20", seed=1, index="0..2").page == several.page
    with pytest.raises(ValueError, match="3 throws"):
        several.rows
    # In a notebook: the page inline, in an iframe of its own.
    import html

    shown = several._repr_html_()
    assert shown.startswith("<iframe") and html.escape(several.page, quote=True) in shown
    assert html.unescape(shown.split('srcdoc="', 1)[1].rsplit('"', 1)[0]) == several.page
    for kwargs, says in [
        (dict(index="0..20"), "at most 16"),
        (dict(index="3..1"), "backwards"),
        (dict(index=range(0, 6, 2)), "consecutive"),
        (dict(every=0), "every"),
        (dict(max_steps=0), "max_steps"),
        (dict(flight="slow"), "flight"),
        (dict(html=tmp_path / "no" / "such" / "dir" / "t.html"), "t.html"),
    ]:
        with pytest.raises((ValueError, OSError), match=says):
            dicephys.trace(shape="d20", **kwargs)  # type: ignore[arg-type]


def test_fair_within_is_every_face_s_2_sigma_as_a_probability() -> None:
    # within=0.02 is the command line's --within 2 (percentage points); precision= its old name.
    want = cli("fair", "--block", "16x16x16", "--within", "2", "--seed", "3", "--json")
    got = dicephys.fair("16x16x16", within=0.02, seed=3)
    assert got.faces == want["summary"]["faces"]
    assert got.result["precision"]["resolved"] is True
    with pytest.warns(DeprecationWarning):
        old = dicephys.fair("16x16x16", precision=0.02, seed=3)
    assert old.faces == got.faces


ROWS = [
    {"label": "a", "surface": "mdf", "length_mm": 140, "breadth_mm": 24, "width_mm": 20, "mode": "2d",
     "length_vertical": 0, "breadth_vertical": 0, "width_vertical": 0},
    {"label": "b", "surface": "mdf", "length_mm": 140, "breadth_mm": 22, "width_mm": 13, "mode": "2d",
     "length_vertical": 0, "breadth_vertical": 0, "width_vertical": 0},
]


def test_a_fit_recovers_known_values_at_a_tiny_size(tmp_path: Path) -> None:
    rows = [dict(r, breadth_vertical=4000, width_vertical=6000) for r in ROWS]
    res = dicephys.recover(rows, {"e": 0.5}, repeats=4, points=8, point_rolls=400, refine=False, out=tmp_path / "rec")
    assert res.names == ["e[mdf]"] and res.truth == [0.5]
    assert len(res.repetitions) == 4
    # Each repetition's estimate near the truth, and the truth inside most 2σ regions (a
    # tiny size: the coverage itself is measured at scale in docs/results/calibration.md).
    for r in res.repetitions:
        assert abs(r["values"][0] - 0.5) < 0.25
    assert res.coverage >= 0.5


def test_fit_then_predict_through_python(tmp_path: Path) -> None:
    rows = [dict(r, breadth_vertical=4100, width_vertical=5900) for r in ROWS]
    f = dicephys.fit(rows, free=["e"], points=8, point_rolls=300, refine=False, out=tmp_path / "fit")
    assert Path(f.path).exists()
    assert repr(f).startswith("Fit(e[mdf] ") and "\n" not in repr(f)
    assert f.summary() == (tmp_path / "fit" / "report.md").read_text(encoding="utf-8")
    p = dicephys.predict(f, "140x30x10", mode="2d", draws=4, rolls=200)
    want = cli("predict", "--fit", f.path, "--block", "140x30x10", "--2d", "--draws", "4", "--rolls", "200", "--json")
    assert p.data == want


def test_a_fit_s_discrepancy_widens_its_predictions_through_python_as_on_the_cli(tmp_path: Path) -> None:
    # With κ alone free, the paper's rows predicted without themselves miss beyond their
    # errors (three surfaces, e and μ held): the fit learns a discrepancy (a line on the
    # log-odds) and moves and widens every prediction by it.
    f = dicephys.fit("paper", free=["kappa"], points=8, point_rolls=100, degree=1, dt=1 / 250, seed=2,
                     out=tmp_path / "fit")
    asked = [o for o in f.discrepancy["outcomes"] if o["asked"]]
    assert asked and all(o["p_value"] < 0.05 for o in asked)
    p = dicephys.predict(f, "140x30x10", draws=3, rolls=50)
    assert p.data["discrepancy"] == f.discrepancy
    for q in p.data["p"][1:]:
        assert q["err_model"] > 0
        assert abs(q["err"] ** 2 - (q["err_params"] ** 2 + q["err_sim"] ** 2 + q["err_model"] ** 2)) < 1e-12
    want = cli("predict", "--fit", f.path, "--block", "140x30x10", "--draws", "3", "--rolls", "50", "--json")
    assert p.data == want


def test_two_models_compared_through_python_are_the_cli_s(tmp_path: Path) -> None:
    third = dict(ROWS[0], label="c", breadth_mm=30, width_mm=10)
    rows = [dict(r, breadth_vertical=b, width_vertical=1000 - b) for r, b in zip(ROWS + [third], (410, 260, 80))]
    small = dict(points=12, point_rolls=300, degree=2, max_degree=2, refine=False)
    one = dicephys.fit(rows, free=["e"], out=tmp_path / "e", **small)  # type: ignore[arg-type]
    two = dicephys.fit(rows, free=["e", "mu"], out=tmp_path / "emu", **small)  # type: ignore[arg-type]
    assert [r["label"] for r in one.loo] == ["a", "b", "c"]
    got = dicephys.compare(two, one)
    assert got.decision["outcome"] in ("richer", "simpler", "unresolved")
    assert [m["name"] for m in got.models] == ["e", "e,mu"]
    want = cli("compare", two.path, one.path, "--json")
    assert got.data == want
    with pytest.raises(ValueError, match="no row was predicted without itself"):
        dicephys.compare(dicephys.fit(rows[:2], free=["e"], out=tmp_path / "two", **small), one)  # type: ignore[arg-type]


def test_a_die_s_weight_fitted_through_python_is_the_cli_s(tmp_path: Path) -> None:
    faces = dicephys.roll("16x16x16", rolls=1500, seed=5, throw="tumble", com=(0, 0, -1)).data["faces"]
    row = dict(label="suspect", surface="MDF", length_mm=16, breadth_mm=16, width_mm=16, mode="3d")
    row.update({f"face_{k}": faces[str(k)] for k in range(1, 7)})
    f = dicephys.fit([row], free=["com_z"], kappa=0, points=8, point_rolls=300, refine=False,
                     out=tmp_path / "py")
    csv_path = tmp_path / "suspect.csv"
    csv_path.write_text(",".join(row) + "\n" + ",".join(str(v) for v in row.values()) + "\n")
    want = cli("fit", "--data", str(csv_path), "--free", "com_z", "--kappa", "0", "--points", "8",
               "--point-rolls", "300", "--no-refine", "--out", str(tmp_path / "cli"), "--json")
    got, wanted = f.data["estimate"]["params"][0], want["estimate"]["params"][0]
    assert got["value"] == wanted["value"] and got["two_sigma"] == wanted["two_sigma"]
    assert got["two_sigma"][0] <= -1.0 <= got["two_sigma"][1]


def test_a_d4_s_weight_fitted_and_predicted_through_python_is_the_cli_s(tmp_path: Path) -> None:
    # A die of any shape: counts by face_<label>, predicted without a block.
    faces = dicephys.roll(shape="d4", rolls=1200, seed=5, com=(0, 0, -1)).faces
    row: Dict[str, Any] = dict(label="suspect", surface="MDF")
    row.update({f"face_{k}": v for k, v in faces.items()})
    small = dict(free=["com_z"], points=8, point_rolls=200, refine=False, dt=1 / 250)
    f = dicephys.fit([row], shape="d4", out=tmp_path / "py", **small)  # type: ignore[arg-type]
    csv_path = tmp_path / "d4.csv"
    csv_path.write_text(",".join(row) + "\n" + ",".join(str(v) for v in row.values()) + "\n")
    want = cli("fit", "--data", str(csv_path), "--shape", "d4", "--free", "com_z", "--points", "8",
               "--point-rolls", "200", "--no-refine", "--dt", "1/250", "--out", str(tmp_path / "cli"),
               "--json")
    assert f.data["estimate"]["params"][0]["value"] == want["estimate"]["params"][0]["value"]
    p = dicephys.predict(f, draws=3, rolls=100)
    assert p.data == cli("predict", "--fit", f.path, "--draws", "3", "--rolls", "100", "--json")
    assert p.data["shape"] == "d4" and len(p.data["faces"]) == 4
    assert sorted(p.data["labels"]) == ["1", "2", "3", "4"]
    # Issue 71.2: another die from the d4's calibration, scored against its counts, as the CLI.
    d6 = "label,surface,face_1,face_2,face_3,face_4,face_5,face_6\nd,MDF,9,11,10,10,8,12\n"
    (tmp_path / "d6.csv").write_text(d6)
    other = dicephys.predict(f, shape="d6", counts=d6, draws=3, rolls=100)
    assert other.data == cli("predict", "--fit", f.path, "--shape", "d6", "--counts",
                             str(tmp_path / "d6.csv"), "--draws", "3", "--rolls", "100", "--json")
    assert other.data["other_die"] == "d6"
    assert set(other.data["tests"][0]["scores"]) == {"prediction", "default_scene", "quasi_static"}


@pytest.mark.usefixtures("sigint_raises")
def test_paper_is_the_cli_s_and_a_stopped_one_writes_nothing(tmp_path: Path) -> None:
    # Stopped half a second in: KeyboardInterrupt, and no results.json half-written.
    stopped = tmp_path / "stopped"
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        dicephys.paper(stopped, rolls=200_000, engines=["bullet"])
    assert not (stopped / "results.json").exists()

    got = dicephys.paper(tmp_path / "py", rolls=200, engines=["bullet"])
    subprocess.run(
        [BIN, "paper", "--rolls", "200", "--engines", "bullet", "--out", str(tmp_path / "cli")],
        check=True, capture_output=True,
    )
    want = json.loads((tmp_path / "cli" / "results.json").read_text())
    assert got.data == json.loads((tmp_path / "py" / "results.json").read_text())
    def cells(doc: dict) -> list:
        return [(c["label"], c["mode"], c["engine"], c["run"]["counts"]) for c in doc["simulations"]]

    assert len(cells(want)) == 10 and cells(got.data) == cells(want)


def test_an_unknown_option_is_a_type_error() -> None:
    with pytest.raises(TypeError, match="colour"):
        dicephys.fair("16x16x16", rolls=10, colour="red")


# A design of the loaded d6's weight (P(1) = 1/4), small: three values a scan, 100 throws each.
DESIGN_ARGS = ("--block", "16x16x16", "--free", "com_z", "--range", "com_z=-3:0",
               "--rolls", "100", "--points", "3", "--check-rolls", "200", "--seed", "1")


def test_design_is_the_cli_s_design_with_a_named_target_and_a_fit(tmp_path: Path) -> None:
    # Issue 73: dicephys.design() returns design --json's document, the same numbers.
    want = cli("design", *DESIGN_ARGS, "--target", "1=1/4,rest=3/4", "--json")
    kw: Dict[str, Any] = dict(free="com_z", range=(-3, 0), rolls=100, points=3, check_rolls=200, seed=1)
    got = dicephys.design("16x16x16", target={"1": 0.25, "rest": 0.75}, threads=2, **kw)
    assert isinstance(got, dicephys.Design)
    assert got.data == want
    assert got.summary().startswith("design: com_z of 16x16x16 mm")
    assert repr(got).startswith("Design(com_z = ")
    # Under a fit's calibration (a cube's faces, μ free, e held at 0.9), written with --out.
    csv = tmp_path / "cube.csv"
    csv.write_text("label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,"
                   "face_4,face_5,face_6\nd,felt,16,16,16,3d,170,160,170,165,170,165\n")
    subprocess.run([BIN, "fit", "--data", str(csv), "--free", "mu", "--restitution", "0.9",
                    "--points", "6", "--rolls", "100", "--degree", "1", "--no-refine", "--dt",
                    "1/250", "--seed", "1", "--out", str(tmp_path / "fit")],
                   check=True, capture_output=True)
    fit = str(tmp_path / "fit" / "fit.json")
    want = cli("design", *DESIGN_ARGS, "--target", "1=1/4,rest=3/4", "--fit", fit, "--json")
    got = dicephys.design("16x16x16", target="1=1/4,rest=3/4", fit=fit, out=tmp_path / "d", **kw)
    assert got.data == want
    assert got.config["calibration"]["values"]["e"] == 0.9
    assert json.loads((tmp_path / "d" / "design.json").read_text()) == want
    assert (tmp_path / "d" / "design.svg").is_file() and (tmp_path / "d" / "design.png").is_file()
    # A named target is refused where the die's labels are not its numbers; a scene option
    # beside a fit, which sets the scene.
    with pytest.raises(ValueError, match="'1' is not among them"):
        dicephys.design("16x16x16", target="2d6", **kw)
    with pytest.raises(ValueError, match="friction"):
        dicephys.design("16x16x16", target="1=1/4,rest=3/4", fit=fit, friction=0.3, **kw)


def test_a_design_of_a_dies_facets_is_the_cli_s(tmp_path: Path) -> None:
    # Issue 73, the mesh family: V1 numbered (tests/data's mesh), its facets designed for 2d6
    # in one small round; the same document as the command line's, its die file written.
    root = Path(__file__).resolve().parents[2]
    text = (root / "docs/results/real-dice/v1-numbers.toml").read_text()
    mesh = root / "tests/data/hendecahedron_v1.obj"
    die = tmp_path / "v1.toml"
    die.write_text("\n".join(f'mesh = "{mesh}"' if line.startswith("mesh = ") else line
                             for line in text.splitlines()))
    args = ("--die", str(die), "--free", "facets", "--range", "facets=-2:2", "--target", "2d6",
            "--rolls", "100", "--rounds", "1", "--check-rolls", "100", "--seed", "1")
    want = cli("design", *args, "--json")
    got = dicephys.design(die=die, free="facets", range=(-2, 2), target="2d6", rolls=100,
                          rounds=1, check_rolls=100, seed=1, threads=2, out=tmp_path / "d")
    assert got.data == want
    assert repr(got).startswith("Design(facets moved up to ")
    assert len(got.data["faces"]) == 11 and got.data["by_class"]["check"]["dof"] == 5
    assert (tmp_path / "d" / "design.toml").is_file() and (tmp_path / "d" / "design.obj").is_file()
    with pytest.raises(ValueError, match="not scans"):
        dicephys.design(die=die, free="facets", range=(-2, 2), target="2d6", points=3)
