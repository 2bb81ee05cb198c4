"""Figure 3 of the paper: the flip-symmetric branch at z* = 0.115,
δ = 0.05 followed in φ from the Appendix D knot, Tw against φ/2π, coloured
by stability and good knots, with its events W1, W2, X and S — drawn with
matplotlib (optional: ``pip install matplotlib``).

    python python/examples/figure_3.py [OUT.png] [N]
"""

import pathlib
import sys

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(out: str = "figure_3.png", segments: int = 100) -> pathlib.Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene = knotrod.Scene.from_toml(ROOT / "scenes/fig3_kirchhoff.toml")
    branch = knotrod.branch(scene, segments=segments)
    cols = branch.columns()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for b in sorted(set(cols["branch"])):
        on = cols["branch"] == b
        for leg in sorted(set(cols["leg"][on])):
            sel = on & (cols["leg"] == leg)
            ax.plot(cols["phi_over_2pi"][sel], cols["twist"][sel], "-", color="0.7", lw=0.8, zorder=1)
    for mask, style, label in (
        (~cols["stable"], dict(color="tab:red", s=4), "unstable"),
        (cols["stable"] & ~cols["good_knot"], dict(color="tab:blue", s=4), "stable"),
        (cols["good_knot"], dict(color="tab:green", s=8), "good knot"),
    ):
        ax.scatter(cols["phi_over_2pi"][mask], cols["twist"][mask], label=label, zorder=2, **style)
    for e in branch.events:
        if e.label in ("W1", "W2", "X", "S") and e.branch == 0:
            ax.annotate(e.label, (e.phi_over_2pi, e.twist), textcoords="offset points", xytext=(4, 4))
            ax.plot(e.phi_over_2pi, e.twist, "k+", zorder=3)
    ax.set_xlabel("φ/2π")
    ax.set_ylabel("Tw")
    ax.set_title(f"Figure 3: z* = 0.115, δ = 0.05, N = {segments}")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    path = pathlib.Path(out)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    print(f"{len(branch)} equilibria, events {[e.label for e in branch.events if e.label]}; wrote {path}")
    return path


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "figure_3.png", int(sys.argv[2]) if len(sys.argv) > 2 else 100)
