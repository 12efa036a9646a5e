"""
Speed against error: the figures
================================

The PNGs of ``benchmarks/speed_vs_error.py`` (matplotlib, Agg), from what
it measured; nothing here times or fits anything
(``tests/benchmarks/test_speed_vs_error.py`` draws them from small inputs).

-   :func:`figure_speed_vs_error`: error against cost, one panel per plane.
-   :func:`figure_batch`: a batch report's distribution per model kind.
-   :func:`figure_fit_settings`: fit time against error per fitting setting.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.speed_vs_error_report import batch_label, batch_rows

__all__ = ["figure_speed_vs_error", "figure_batch", "figure_fit_settings"]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_speed_vs_error(path: Path, panels: list[dict[str, Any]]) -> None:
    """
    One log-log panel of mean Delta E 2000 against cost per entry of
    ``panels``: ``title``, ``xlabel``, ``points`` {label: (cost, error,
    marker size)} and ``front`` (labels, in cost order). A zero error is drawn
    on the axis floor, 1e-3.
    """
    plt = _pyplot()
    floor = 1e-3
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4.8), constrained_layout=True)
    for ax, panel in zip(np.atleast_1d(axes), panels):
        costs = [cost for cost, _, _ in panel["points"].values()]
        for index, (label, (cost, error, size)) in enumerate(panel["points"].items()):
            ax.scatter(cost, max(error, floor), s=size, zorder=3, color=f"C{index % 10}")
            # Labels alternate above and below their point: neighbours of equal error overlap less.
            ax.annotate(
                label,
                (cost, max(error, floor)),
                textcoords="offset points",
                xytext=(5, 4 if index % 2 == 0 else -10),
                fontsize=7,
            )
        if panel["front"]:
            ax.plot(
                [panel["points"][m][0] for m in panel["front"]],
                [max(panel["points"][m][1], floor) for m in panel["front"]],
                "k--",
                lw=1,
                zorder=2,
                label="Pareto front",
            )
            ax.legend(loc="lower left", fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        # Room on the right for the labels of the costliest points.
        ax.set_xlim(min(costs) / 1.3, max(costs) * 6)
        ax.set_title(panel["title"], fontsize=9)
        ax.set_xlabel(panel["xlabel"], fontsize=9)
        ax.set_ylabel("mean Delta E 2000, 22 conductors")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("Speed against error (marker area grows with bytes per material)", fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_batch(path: Path, reports: list[dict[str, Any]], names: list[str]) -> None:
    """The share of fitted pages at or below each mean Delta E 2000 (an empirical CDF), one
    panel per batch report, one line per name of ``names`` the report holds."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(reports), figsize=(6 * len(reports), 4.4), constrained_layout=True, squeeze=False)
    for ax, report in zip(axes[0], reports):
        fitted = [p for p in report["pages"] if p["status"] == "fitted"]
        held = {r["name"] for r in batch_rows(report)}
        for index, name in enumerate(names):
            if name not in held:
                continue
            values = np.sort([p[f"{name}_delta_E_mean"] for p in fitted])
            # One colour per name in every panel; the yardstick dashed.
            ax.step(
                np.maximum(values, 1e-3),
                np.arange(1, values.size + 1) / values.size,
                where="post",
                label=name,
                color=f"C{index}",
                ls="--" if name == "lazanyi_adjusted" else "-",
            )
        ax.set_xscale("log")
        ax.set_xlabel("mean Delta E 2000 of a page (100 x 100, eta_i 1-2.5)")
        ax.set_ylabel("share of fitted pages at or below")
        ax.set_title(f"batch {batch_label(report)}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_fit_settings(path: Path, fit_rows: list[dict], fit_front: list[str], key, conductors: int) -> None:
    """Fit time per conductor against mean float16 Delta E 2000 for every fitting setting,
    by objective, with the front (``key(row)`` names a row) and the default circled."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.8), constrained_layout=True)
    markers = {"rgb": "s", "lab": "^", "de2000": "o"}

    def ms(row):
        return row["seconds"] / conductors * 1e3

    for objective in dict.fromkeys(r["objective"] for r in fit_rows):
        pts = [r for r in fit_rows if r["objective"] == objective]
        ax.scatter(
            [ms(r) for r in pts],
            [r["mean"] for r in pts],
            marker=markers.get(objective, "o"),
            label=objective,
            alpha=0.8,
        )
    front_rows = sorted((r for r in fit_rows if key(r) in fit_front), key=lambda r: r["seconds"])
    ax.plot([ms(r) for r in front_rows], [r["mean"] for r in front_rows], "k--", lw=1, label="Pareto front")
    default = next(r for r in fit_rows if r["default"])
    ax.scatter([ms(default)], [default["mean"]], s=160, facecolors="none", edgecolors="red", label="default setting")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("fit time per conductor (ms)")
    ax.set_ylabel(f"mean Delta E 2000 (float16), {conductors} conductors")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
