"""
Speed against error
===================

For all 22 library conductors, every Fresnel model on the speed-against-error
plane, and the fitting settings on the fit-time-against-error plane; prints
Markdown tables and (``--figure``) writes ``docs/images/speed_vs_error.png``
and ``docs/images/speed_vs_error_fit_settings.png``.

    .venv/bin/python benchmarks/speed_vs_error.py [--figure] [--repeats 7] [--models-only]
        [--batch-report DIR/report.json] [--batch-only]

``--batch-report`` adds the accuracy summary of a ``python -m fitting batch``
report (e.g. ``--shelf main``): over every fitted page, the distribution of
the mean Delta E 2000 of each model kind and baseline (mean, median, p90,
max, share of pages in bins), and the share of pages where each kind beats
adjusted Lazanyi; ``--batch-only`` prints only that.

Models: Schlick in air, Schlick with exact F0, adjusted Lazanyi, ours float32,
ours float16, ours scene-specialised (a degree-0 fit at each eta_i row), the
exact RGB conductor Fresnel with n, k fitted in air (``fitting.fits.rgb_conductor.rgb_nk``),
the ``rgb-conductor`` model kind (the same Fresnel, n, k fitted under the coat
over the whole domain, float16: ``fitting.fits.rgb_conductor.fit_rgb_conductor``)
and the exact spectral reference. Error: Delta E 2000 against the 1 nm reference on the paper's
100 x 100 grid (cos theta in [0, 1], eta_i in [1, 2.5]). Shader cost: wall
time of full-screen 2560 x 1440 RGBA32F renders on this machine's GL
(llvmpipe without a GPU), measured with ``preview_shaders.evaluate.time_variants``
as ``benchmarks/shader_cost.py`` does, variants interleaved, median, relative
to adjusted Lazanyi. CPU cost: numpy evaluation per sample (median of 3 runs
over 10^6 samples; 10^4 for the spectral reference). Bytes: per material as a
renderer stores it.

Fitting settings: the grid size (cos theta x eta_i samples, Gauss-Legendre or
uniform), the spectral step
of the fitting reference and the objective, in full cross product; for each,
the summed fit time of the 22 conductors and their mean float16 Delta E.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import evaluation_grid, reference_ACEScg, spectral_grid
from fitting.fits.material import fit_material
from fitting.fits.rgb_conductor import fit_rgb_conductor, rgb_nk
from fitting.fits.settings import OBJECTIVES, FitSettings
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted, schlick
from fitting.models.coated_conductor import (
    coated_conductor_model,
    collapse_to_eta_i,
    model_from_parameters,
)
from fitting.models.pack import halves_to_uint32, to_float16
from fitting.models.rgb_conductor import rgb_conductor_model, rgb_fresnel_conductor
from fitting.optics.library import LIBRARY_NAMES, library_material

IMAGES = ROOT / "docs" / "images"
GRID = 100
WIDTH, HEIGHT = 2560, 1440

MODELS = {
    # name: (label, shader variant or None, bytes per material, how stored)
    "schlick_air": ("Schlick, air F0", "schlick", 12, "F0 RGB, 3 float32"),
    "schlick_exact_F0": ("Schlick, exact F0", "schlick", 12,
                         "F0 RGB at the scene's eta_i, 3 float32 (a table for varying eta_i)"),
    "lazanyi_adjusted": ("adjusted Lazanyi", "lazanyi", 24, "F0, F82 RGB, 6 float32"),
    "ours_float32": ("ours, float32", "floats", 108, "27 float32"),
    "ours_float16": ("ours, float16", "packed", 54, "27 float16"),
    "ours_scene": ("ours, scene-specialised", "collapsed", 18, "9 float16 at one eta_i"),
    "exact_rgb": ("exact RGB conductor Fresnel", "exact", 24, "n, k RGB, 6 float32"),
    "rgb_conductor": ("rgb-conductor kind, float16", "rgb_conductor", 12,
                      "n, k RGB fitted under the coat, 6 float16"),
    "spectral": ("exact spectral reference", None, 2 * 4 * spectral_grid(1.0).size,
                 "n, k at 471 wavelengths (1 nm), float32"),
}


FIT_FAILURES: list[str] = []
"""Degree-0 fits the fitting core refused (an issue of the core, reported):
for those rows the general fit collapsed to the row's eta_i is used."""


def _scene_rows(nk, eta_rows, general) -> np.ndarray:
    """(rows, 3, 3) F0, a, alpha of a degree-0 float16 fit at each eta_i row."""
    rows = []
    for eta in eta_rows:
        domain = (float(eta), float(eta))
        try:
            C = fit_material(nk, domain).coefficients_float16
        except ValueError as error:
            FIT_FAILURES.append(f"{nk.name} at eta_i = {eta:.4f}: {error}")
            C = to_float16(collapse_to_eta_i(general.coefficients_float16, eta, general.eta_i_range))
        rows.append(C[..., 0].astype(np.float64))
    return np.stack(rows)


def model_outputs(name: str) -> dict[str, np.ndarray]:
    """Every model on the 100 x 100 grid for one conductor, with the reference."""
    nk = library_material(name)
    M, E = evaluation_grid(GRID)
    ref = reference_ACEScg(nk, M, E)
    air = baseline_inputs(nk)
    exact_F0 = reference_ACEScg(nk, np.ones_like(E), E)
    fit = fit_material(nk)
    P = _scene_rows(nk, E[:, 0], fit)
    n_rgb, k_rgb = rgb_nk(nk)
    rgb = fit_rgb_conductor(nk)
    return {
        "reference": ref,
        "schlick_air": schlick(M, air["F0_air"]),
        "schlick_exact_F0": schlick(M, exact_F0),
        "lazanyi_adjusted": lazanyi_adjusted(M, E, air["F0_air"], air["F82_air"]),
        "ours_float32": coated_conductor_model(M, E, fit.coefficients.astype(np.float32)),
        "ours_float16": coated_conductor_model(M, E, fit.coefficients_float16),
        "ours_scene": model_from_parameters(M[..., None], P[:, None, 0], P[:, None, 1], P[:, None, 2]),
        "exact_rgb": rgb_fresnel_conductor(M, E, n_rgb, k_rgb),
        "rgb_conductor": rgb_conductor_model(M, E, rgb.coefficients_float16),
        "spectral": ref,
        "_fit": fit,
        "_air": air,
        "_rgb": (n_rgb, k_rgb),
    }


def cpu_cost_ns(repeats: int = 3) -> dict[str, float]:
    """numpy evaluation cost per sample (ns), median of ``repeats``."""
    nk = library_material("Au")
    fit = fit_material(nk)
    air = baseline_inputs(nk)
    n_rgb, k_rgb = rgb_nk(nk)
    C16 = fit_rgb_conductor(nk).coefficients_float16
    rng = np.random.default_rng(0)
    count = 1_000_000
    mu, eta = rng.uniform(0, 1, count), rng.uniform(1, 2.5, count)
    P = fit.coefficients_float16[..., 0].astype(np.float64)
    F0_table = reference_ACEScg(nk, np.ones(64), np.linspace(1, 2.5, 64))
    calls = {
        "schlick_air": lambda: schlick(mu, air["F0_air"]),
        # Exact F0 looked up from a 64-entry table per eta_i.
        "schlick_exact_F0": lambda: schlick(mu, F0_table[np.minimum((eta - 1) / 1.5 * 63, 63).astype(int)]),
        "lazanyi_adjusted": lambda: lazanyi_adjusted(mu, eta, air["F0_air"], air["F82_air"]),
        "ours_float32": lambda: coated_conductor_model(mu, eta, fit.coefficients.astype(np.float32)),
        "ours_float16": lambda: coated_conductor_model(mu, eta, fit.coefficients_float16),
        "ours_scene": lambda: model_from_parameters(mu[:, None], P[0], P[1], P[2]),
        "exact_rgb": lambda: rgb_fresnel_conductor(mu, eta, n_rgb, k_rgb),
        "rgb_conductor": lambda: rgb_conductor_model(mu, eta, C16),
    }
    out = {}
    for name, call in calls.items():
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            call()
            times.append(time.perf_counter() - start)
        out[name] = float(np.median(times)) / count * 1e9
    small = 10_000
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        reference_ACEScg(nk, mu[:small], eta[:small])
        times.append(time.perf_counter() - start)
    out["spectral"] = float(np.median(times)) / small * 1e9
    return out


def shader_cost(repeats: int) -> dict[str, float]:
    """Median wall time (us) of each shader variant at 2560 x 1440."""
    from preview_shaders.evaluate import VARIANTS, shader_inputs, time_variants
    from preview_shaders.gl import RenderThread

    nk = library_material("Au")
    packed = fit_material(nk).packed
    air = baseline_inputs(nk)
    n_rgb, k_rgb = rgb_nk(nk)
    inputs = shader_inputs(packed, 1.5, air["F0_air"], air["F82_air"], n_rgb, k_rgb)
    inputs = dataclasses.replace(
        inputs, rgb_words=halves_to_uint32(fit_rgb_conductor(nk).coefficients_float16)
    )
    with RenderThread("speed-vs-error") as thread:
        samples = time_variants(thread, inputs, VARIANTS, WIDTH, HEIGHT, repeats)
    return {v: float(np.median(s[:, 1])) * 1e6 for v, s in samples.items()}


def pareto_front(points: dict[str, tuple[float, float]]) -> list[str]:
    """Names not dominated in (cost, error): nothing else is no worse in both and better in one."""
    front = []
    for name, (cost, error) in points.items():
        dominated = any(
            (c <= cost and e <= error) and (c < cost or e < error)
            for other, (c, e) in points.items() if other != name
        )
        if not dominated:
            front.append(name)
    return sorted(front, key=lambda n: points[n][0])


def model_table(repeats: int):
    per_material = {}
    for name in LIBRARY_NAMES:
        out = model_outputs(name)
        ref = out["reference"]
        per_material[name] = {
            model: delta_E_map(ref, out[model]) for model in MODELS
        }
    rows = {}
    for model in MODELS:
        means = {m: float(per_material[m][model].mean()) for m in LIBRARY_NAMES}
        maxes = {m: float(per_material[m][model].max()) for m in LIBRARY_NAMES}
        worst = max(means, key=means.get)
        rows[model] = {
            "mean": float(np.mean(list(means.values()))),
            "max": max(maxes.values()),
            "worst": worst,
            "worst_mean": means[worst],
            "worst_max": maxes[worst],
        }
    return rows


def fit_settings_table():
    grids = [(8, 3, "gauss"), (12, 4, "gauss"), (16, 6, "gauss"), (24, 8, "gauss"),
             (16, 6, "uniform"), (24, 7, "uniform")]
    steps = [1.0, 5.0, 10.0, 20.0]
    references = {}
    M, E = evaluation_grid(GRID)
    for name in LIBRARY_NAMES:
        references[name] = reference_ACEScg(library_material(name), M, E)
    rows = []
    for (mu_n, eta_n, kind), step, objective in itertools.product(grids, steps, OBJECTIVES):
        settings = FitSettings(mu_samples=mu_n, eta_samples=eta_n, grid=kind, step_nm=step,
                               objective=objective)
        seconds, errors = 0.0, []
        for name in LIBRARY_NAMES:
            fit = fit_material(library_material(name), settings=settings)
            seconds += fit.timings["total"]
            model = coated_conductor_model(M, E, fit.coefficients_float16)
            errors.append(float(delta_E_map(references[name], model).mean()))
        rows.append({
            "grid": f"{mu_n}x{eta_n} {kind}", "step_nm": step, "objective": objective,
            "seconds": seconds, "mean": float(np.mean(errors)), "max_mean": float(np.max(errors)),
            "default": settings == FitSettings(),
        })
    return rows


def _figures(rows, cpu, shader, fit_rows, front_shader, front_cpu, fit_front) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    IMAGES.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6), constrained_layout=True)
    floor = 1e-3  # the reference has zero error: drawn on the floor of the log axis
    for ax, costs, front, xlabel in (
        (axes[0], {m: shader[MODELS[m][1]] / shader["lazanyi"] for m in MODELS if MODELS[m][1]} if shader else {},
         front_shader, f"shader cost at {WIDTH} x {HEIGHT}, relative to adjusted Lazanyi (llvmpipe)"),
        (axes[1], cpu, front_cpu, "CPU cost per sample (ns, numpy)"),
    ):
        for model, cost in costs.items():
            error = max(rows[model]["mean"], floor)
            ax.scatter(cost, error, s=20 + MODELS[model][2] / 8, zorder=3)
            ax.annotate(MODELS[model][0], (cost, error), textcoords="offset points", xytext=(5, 4), fontsize=8)
        if front:
            ax.plot([costs[m] for m in front], [max(rows[m]["mean"], floor) for m in front],
                    "k--", lw=1, zorder=2, label="Pareto front")
            ax.legend(loc="upper right", fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel, fontsize=9)
        ax.set_ylabel("mean Delta E 2000, 22 conductors")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("Speed against error (marker area grows with bytes per material)", fontsize=10)
    fig.savefig(IMAGES / "speed_vs_error.png", dpi=110)

    fig, ax = plt.subplots(figsize=(7.5, 4.8), constrained_layout=True)
    markers = {"rgb": "s", "lab": "^", "de2000": "o"}
    for objective in OBJECTIVES:
        pts = [r for r in fit_rows if r["objective"] == objective]
        ax.scatter([r["seconds"] / len(LIBRARY_NAMES) * 1e3 for r in pts], [r["mean"] for r in pts],
                   marker=markers[objective], label=objective, alpha=0.8)
    front_rows = [r for r in fit_rows if _key(r) in fit_front]
    front_rows.sort(key=lambda r: r["seconds"])
    ax.plot([r["seconds"] / len(LIBRARY_NAMES) * 1e3 for r in front_rows], [r["mean"] for r in front_rows],
            "k--", lw=1, label="Pareto front")
    default = next(r for r in fit_rows if r["default"])
    ax.scatter([default["seconds"] / len(LIBRARY_NAMES) * 1e3], [default["mean"]], s=160,
               facecolors="none", edgecolors="red", label="default setting")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("fit time per conductor (ms)")
    ax.set_ylabel("mean Delta E 2000 (float16), 22 conductors")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(IMAGES / "speed_vs_error_fit_settings.png", dpi=110)


def _key(row) -> str:
    return f"{row['grid']} {row['step_nm']:g} nm {row['objective']}"


BATCH_BINS = (0.0, 0.5, 1.0, 2.0, 5.0, 10.0, float("inf"))


def batch_report_table(path: Path) -> None:
    """Print the accuracy summary of a batch report (``report.json``)."""
    import json

    report = json.loads(Path(path).read_text(encoding="utf-8"))
    summary, config = report["summary"], report["config"]
    fitted = [p for p in report["pages"] if p["status"] == "fitted"]
    names = list(config["model_kinds"]) + list(config["baselines"])
    print(f"## Database batch: {summary['fitted']} of {summary['pages']} pages fitted "
          f"({summary['skipped']} skipped, {summary['failed']} failed), grid {config['grid']}, "
          f"eta_i {config['eta_i_range'][0]:g}-{config['eta_i_range'][1]:g}\n")
    bins = [f"{lo:g}-{hi:g}" if hi != float("inf") else f">{lo:g}"
            for lo, hi in zip(BATCH_BINS[:-1], BATCH_BINS[1:])]
    print("| model | mean | median | p90 | max | " + " | ".join(f"share {b}" for b in bins)
          + " | beats adj. Lazanyi |")
    print("|---|" + "---:|" * (4 + len(bins) + 1))
    for name in names:
        e = summary["delta_E_mean"][name]
        if not e["pages"]:
            continue
        values = np.array([p[f"{name}_delta_E_mean"] for p in fitted])
        shares = np.histogram(values, bins=np.array(BATCH_BINS))[0] / values.size
        beats = e.get("beats_lazanyi_adjusted")
        print(f"| {name} | {e['mean']:.3f} | {e['median']:.3f} | {e['p90']:.3f} | {e['max']:.2f} | "
              + " | ".join(f"{v:.0%}" for v in shares)
              + f" | {'' if beats is None else format(beats, '.1%')} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description="Speed against error for the 22 conductors.")
    parser.add_argument("--batch-report", type=Path, metavar="REPORT_JSON",
                        help="add the accuracy summary of a python -m fitting batch report.json")
    parser.add_argument("--batch-only", action="store_true", help="print only the batch summary")
    parser.add_argument("--figure", action="store_true", help="write the two PNGs to docs/images/")
    parser.add_argument("--repeats", type=int, default=7, help="shader timing rounds")
    parser.add_argument("--models-only", action="store_true",
                        help="the models table only (skip the fitting-settings sweep)")
    args = parser.parse_args()
    if args.batch_report is not None:
        batch_report_table(args.batch_report)
        if args.batch_only:
            return
    elif args.batch_only:
        parser.error("--batch-only needs --batch-report")

    t0 = time.perf_counter()
    rows = model_table(args.repeats)
    cpu = cpu_cost_ns()
    shader = shader_cost(args.repeats)
    shader_ratio = {
        m: (shader[MODELS[m][1]] / shader["lazanyi"] if shader and MODELS[m][1] else None) for m in MODELS
    }
    front_shader = pareto_front({m: (shader_ratio[m], rows[m]["mean"]) for m in MODELS if shader_ratio[m]})
    front_cpu = pareto_front({m: (cpu[m], rows[m]["mean"]) for m in MODELS})
    front_bytes = pareto_front({m: (MODELS[m][2], rows[m]["mean"]) for m in MODELS})

    print(f"## Models: {len(LIBRARY_NAMES)} conductors, {GRID} x {GRID} grid, Delta E 2000 against the 1 nm reference\n")
    print("| model | mean dE (22) | max dE (22) | worst conductor: mean / max | shader cost vs adj. Lazanyi "
          "| CPU ns/sample | bytes/material | on front (shader / CPU / bytes) |")
    print("|---|---:|---:|---|---:|---:|---:|---|")
    for m, (label, _, size, _) in MODELS.items():
        r = rows[m]
        ratio = f"{shader_ratio[m]:.2f}x" if shader_ratio[m] else "n/a (no shader)"
        fronts = " / ".join("yes" if m in f else "no" for f in (front_shader, front_cpu, front_bytes))
        print(f"| {label} | {r['mean']:.3f} | {r['max']:.2f} | {r['worst']}: {r['worst_mean']:.3f} / "
              f"{r['worst_max']:.2f} | {ratio} | {cpu[m]:.0f} | {size} | {fronts} |")
    if FIT_FAILURES:
        print(f"\nDegree-0 fits refused by the fitting core ({len(FIT_FAILURES)}; the general fit "
              "collapsed to that eta_i is used instead): " + "; ".join(FIT_FAILURES))
    if shader:
        print(f"\nShader wall time (us, median of {args.repeats}, {WIDTH} x {HEIGHT}): "
              + ", ".join(f"{v} {t:.0f}" for v, t in shader.items()))
    print("\nBytes: " + "; ".join(f"{MODELS[m][0]}: {MODELS[m][3]}" for m in MODELS))

    if args.models_only:
        print(f"\nRun time: {time.perf_counter() - t0:.0f} s")
        return
    fit_rows = fit_settings_table()
    fit_front = pareto_front({_key(r): (r["seconds"], r["mean"]) for r in fit_rows})
    print(f"\n## Fitting settings: fit time against error, {len(LIBRARY_NAMES)} conductors\n")
    print("| grid (cos theta x eta_i) | step (nm) | objective | fit time per conductor (ms) "
          "| mean dE (f16) | worst conductor mean dE | on front |")
    print("|---|---:|---|---:|---:|---:|---|")
    for r in sorted(fit_rows, key=lambda r: r["seconds"]):
        name = _key(r)
        mark = " **(default)**" if r["default"] else ""
        print(f"| {r['grid']}{mark} | {r['step_nm']:g} | {r['objective']} | "
              f"{r['seconds'] / len(LIBRARY_NAMES) * 1e3:.1f} | {r['mean']:.4f} | {r['max_mean']:.3f} | "
              f"{'yes' if name in fit_front else ''} |")
    default = next(r for r in fit_rows if r["default"])
    print(f"\nDefault setting ({_key(default)}) on the front: "
          f"**{'yes' if _key(default) in fit_front else 'no'}**")
    if args.figure:
        _figures(rows, cpu, shader, fit_rows, front_shader, front_cpu, fit_front)
        print("\nwrote docs/images/speed_vs_error.png, docs/images/speed_vs_error_fit_settings.png")
    print(f"\n(total {time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
