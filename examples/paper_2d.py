"""The paper's 2D ratio against its theory for the five MDF blocks, from Python.

    python examples/paper_2d.py [ROLLS] [FIGURE.png]

Rolls each MDF block of the paper's table (the rows its own simulation reproduced) in 2D on
Bullet, prints the simulated ratio N(breadth)/N(width) with its error beside the theory
(the paper's eq. 8, "MasterEqu") and the measured ratio, and plots the three against R, the
block's aspect parameter, when matplotlib is installed. docs/python.md walks through it.
"""

import sys

import dicephys

rolls = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
figure = sys.argv[2] if len(sys.argv) > 2 else "paper_2d.png"

table = dicephys.theory()
blocks = [row for row in table.rows if row["simulated"]]

print(f"{'block':<16} {'R':>6} {'simulated':>16} {'theory':>8} {'measured':>16}")
points = []
for row in blocks:
    block = f"{row['length_mm']:g}x{row['breadth_mm']:g}x{row['width_mm']:g}"
    run = dicephys.roll(block, mode="2d", rolls=rolls, seed=2385)
    sim, theory, measured = run.ratio, row["theory_ratio"], row["measured_ratio"]
    points.append((row["r"]["value"], sim, theory["value"], measured))
    print(
        f"{row['label']:<16} {row['r']['value']:6.3f} {sim.value:8.4f} ± {sim.error:.4f} "
        f"{theory['value']:8.4f} {measured['value']:8.4f} ± {measured['err']:.4f}"
    )

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no figure (pip install matplotlib)")
    sys.exit(0)

points.sort()
r = [p[0] for p in points]
fig, ax = plt.subplots(figsize=(6, 4))
ax.errorbar(r, [p[1].value for p in points], yerr=[2 * p[1].error for p in points], fmt="o",
            label=f"Bullet 2D, {rolls:,} rolls (2σ)")
ax.plot(r, [p[2] for p in points], "s-", label="theory (the paper's eq. 8)")
ax.errorbar(r, [p[3]["value"] for p in points], yerr=[2 * p[3]["err"] for p in points], fmt="^",
            label="measured (2σ)")
ax.set_xlabel("R = width / breadth")
ax.set_ylabel("N(breadth) / N(width)")
ax.set_title("The paper's five MDF blocks")
ax.legend()
fig.tight_layout()
fig.savefig(figure, dpi=120)
print(f"wrote {figure}")
