"""
Speed against error
===================

For all 22 library conductors, every Fresnel model on the speed-against-error
plane, every model kind side by side, the split-sum variants of image-based
lighting, the accuracy summary of database batch reports, and the fitting
settings on the fit-time-against-error plane; prints Markdown tables (headed
by the command, the date and the load average) and (``--figure``) writes
``docs/images/speed_vs_error.png``, ``docs/images/speed_vs_error_fit_settings.png``
and, with ``--batch-report``, ``docs/images/speed_vs_error_batch.png``.

    .venv/bin/python benchmarks/speed_vs_error.py [--figure] [--repeats 7] [--models-only]
        [--batch-report DIR/report.json ...] [--batch-only]

``--batch-report`` (repeatable) adds the accuracy summary of a ``python -m
fitting batch`` report (e.g. ``--shelf main``): over every fitted page, the
distribution of the mean Delta E 2000 of each model kind and baseline (mean,
median, p90, max, share of pages in bins), and the share of pages where each
kind beats adjusted Lazanyi; the model-kinds table gets one column per
report. ``--batch-only`` prints only the batch summaries.

Models: Schlick in air, Schlick with exact F0, adjusted Lazanyi, ours float32,
every model kind of :data:`fitting.models.kinds.MODEL_KINDS` as shipped
(float16, fitted by :func:`fitting.fits.kinds.fit_model`, evaluated by
:func:`fitting.models.kinds.model_ACEScg`, drawn by the variant
:data:`preview_shaders.evaluate.MODEL_VARIANTS` names), ours scene-specialised
(a degree-0 fit at each eta_i row), the exact RGB conductor Fresnel with n, k
fitted in air (``fitting.fits.rgb_conductor.rgb_nk``) and the exact spectral
reference. Error: Delta E 2000 against the 1 nm reference on the paper's
100 x 100 grid (cos theta in [0, 1], eta_i in [1, 2.5]). Shader cost: wall
time of full-screen 2560 x 1440 RGBA32F renders on this machine's GL
(llvmpipe without a GPU), measured with ``preview_shaders.evaluate.time_variants``
as ``benchmarks/shader_cost.py`` does, variants interleaved, median, relative
to adjusted Lazanyi and per pixel. CPU cost: numpy evaluation per sample
(median of 3 runs over 10^6 samples; 10^4 for the spectral reference).
Bytes: per material as a renderer stores it.

Split sum: ``benchmarks/speed_vs_error_split_sum.py`` (the albedo through the
LUT against the albedo with the spectral Fresnel). Tables:
``benchmarks/speed_vs_error_report.py``; figures:
``benchmarks/speed_vs_error_figures.py``.

Fitting settings (``benchmarks/speed_vs_error_fit_settings.py``): the grid
size (cos theta x eta_i samples, Gauss-Legendre or uniform), the spectral
step of the fitting reference and the objective, in full cross product; for
each, the summed fit time of the 22 conductors and their mean float16 Delta E.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.speed_vs_error_figures import figure_batch, figure_speed_vs_error  # noqa: E402
from benchmarks.speed_vs_error_fit_settings import print_fit_settings  # noqa: E402
from benchmarks.speed_vs_error_report import (  # noqa: E402
    batch_table,
    error_summary,
    kinds_table,
    load_average,
    models_table,
    read_batch_report,
    run_header,
    split_sum_table_lines,
)
from benchmarks.speed_vs_error_split_sum import (  # noqa: E402
    KIND_SPLIT_SUM,
    SPLIT_ETA_I,
    SPLIT_NDOTV,
    SPLIT_ROUGHNESS,
    SPLIT_VARIANTS,
    split_sum_cpu_ns,
    split_sum_shader_us,
    split_sum_table,
)
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.colour.reference import evaluation_grid, reference_ACEScg, spectral_grid  # noqa: E402
from fitting.fits.kinds import fit_model  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.fits.rgb_conductor import rgb_nk  # noqa: E402
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted, schlick  # noqa: E402
from fitting.models.coated_conductor import (  # noqa: E402
    coated_conductor_model,
    collapse_to_eta_i,
    model_from_parameters,
)
from fitting.models.kinds import DEFAULT_MODEL, MODEL_KINDS, coefficient_count, model_ACEScg  # noqa: E402
from fitting.models.pack import halves_to_uint32, to_float16  # noqa: E402
from fitting.models.rgb_conductor import rgb_fresnel_conductor  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402
from preview_shaders.evaluate import MODEL_VARIANTS  # noqa: E402

IMAGES = ROOT / "docs" / "images"
GRID = 100
WIDTH, HEIGHT = 2560, 1440


def kind_label(kind: str) -> str:
    """A model kind's label: "<kind> kind, float16", the default kind (the paper's) marked ours."""
    return f"{kind} kind{' (ours)' if kind == DEFAULT_MODEL else ''}, float16"


MODELS = {
    # name: (label, shader variant or None, bytes per material, how stored)
    "schlick_air": ("Schlick, air F0", "schlick", 12, "F0 RGB, 3 float32"),
    "schlick_exact_F0": (
        "Schlick, exact F0",
        "schlick",
        12,
        "F0 RGB at the scene's eta_i, 3 float32 (a table for varying eta_i)",
    ),
    "lazanyi_adjusted": ("adjusted Lazanyi", "lazanyi", 24, "F0, F82 RGB, 6 float32"),
    "ours_float32": ("ours, float32", "floats", 108, "27 float32"),
    # Every model kind as shipped: float16, named as the batch names it.
    **{
        kind: (
            kind_label(kind),
            MODEL_VARIANTS[kind],
            2 * coefficient_count(kind),
            f"{coefficient_count(kind)} float16",
        )
        for kind in MODEL_KINDS
    },
    "ours_scene": ("ours, scene-specialised", "collapsed", 18, "9 float16 at one eta_i"),
    "exact_rgb": ("exact RGB conductor Fresnel (n, k in air)", "exact", 24, "n, k RGB, 6 float32"),
    "spectral": (
        "exact spectral reference",
        None,
        2 * 4 * spectral_grid(1.0).size,
        "n, k at 471 wavelengths (1 nm), float32",
    ),
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
    fits = {kind: fit_model(nk, model=kind) for kind in MODEL_KINDS}
    fit = fits["coated-conductor"]
    P = _scene_rows(nk, E[:, 0], fit)
    n_rgb, k_rgb = rgb_nk(nk)
    return {
        "reference": ref,
        "schlick_air": schlick(M, air["F0_air"]),
        "schlick_exact_F0": schlick(M, exact_F0),
        "lazanyi_adjusted": lazanyi_adjusted(M, E, air["F0_air"], air["F82_air"]),
        "ours_float32": coated_conductor_model(M, E, fit.coefficients.astype(np.float32)),
        **{kind: model_ACEScg(kind, M, E, f.coefficients_float16, f.eta_i_range) for kind, f in fits.items()},
        "ours_scene": model_from_parameters(M[..., None], P[:, None, 0], P[:, None, 1], P[:, None, 2]),
        "exact_rgb": rgb_fresnel_conductor(M, E, n_rgb, k_rgb),
        "spectral": ref,
    }


def _median_ns(call, count: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times)) / count * 1e9


def cpu_cost_ns(repeats: int = 3) -> dict[str, float]:
    """numpy evaluation cost per sample (ns), median of ``repeats``."""
    nk = library_material("Au")
    fits = {kind: fit_model(nk, model=kind) for kind in MODEL_KINDS}
    fit = fits["coated-conductor"]
    air = baseline_inputs(nk)
    n_rgb, k_rgb = rgb_nk(nk)
    rng = np.random.default_rng(0)
    count = 1_000_000
    mu, eta = rng.uniform(0, 1, count), rng.uniform(1, 2.5, count)
    P = fit.coefficients_float16[..., 0].astype(np.float64)
    F0_table = reference_ACEScg(nk, np.ones(64), np.linspace(1, 2.5, 64))

    def kind_call(kind, f):
        return lambda: model_ACEScg(kind, mu, eta, f.coefficients_float16, f.eta_i_range)

    calls = {
        "schlick_air": lambda: schlick(mu, air["F0_air"]),
        # Exact F0 looked up from a 64-entry table per eta_i.
        "schlick_exact_F0": lambda: schlick(mu, F0_table[np.minimum((eta - 1) / 1.5 * 63, 63).astype(int)]),
        "lazanyi_adjusted": lambda: lazanyi_adjusted(mu, eta, air["F0_air"], air["F82_air"]),
        "ours_float32": lambda: coated_conductor_model(mu, eta, fit.coefficients.astype(np.float32)),
        **{kind: kind_call(kind, f) for kind, f in fits.items()},
        "ours_scene": lambda: model_from_parameters(mu[:, None], P[0], P[1], P[2]),
        "exact_rgb": lambda: rgb_fresnel_conductor(mu, eta, n_rgb, k_rgb),
    }
    out = {name: _median_ns(call, count, repeats) for name, call in calls.items()}
    small = 10_000
    out["spectral"] = _median_ns(lambda: reference_ACEScg(nk, mu[:small], eta[:small]), small, repeats)
    return out


def shader_cost(repeats: int) -> tuple[dict[str, float], str]:
    """Median wall time (us) of each shader variant at 2560 x 1440, and the GL renderer."""
    from preview_shaders.evaluate import VARIANTS, shader_inputs, time_variants
    from preview_shaders.gl import RenderThread

    nk = library_material("Au")
    packed = fit_material(nk).packed
    air = baseline_inputs(nk)
    n_rgb, k_rgb = rgb_nk(nk)
    inputs = shader_inputs(packed, 1.5, air["F0_air"], air["F82_air"], n_rgb, k_rgb)
    inputs = dataclasses.replace(
        inputs, rgb_words=halves_to_uint32(fit_model(nk, model="rgb-conductor").coefficients_float16)
    )
    with RenderThread("speed-vs-error") as thread:
        samples = time_variants(thread, inputs, VARIANTS, WIDTH, HEIGHT, repeats)
        renderer = thread.renderer
    return {v: float(np.median(s[:, 1])) * 1e6 for v, s in samples.items()}, renderer


def model_table() -> dict[str, dict]:
    """Per model: :func:`error_summary` of its Delta E 2000 on the 22 conductors."""
    per_material = {}
    for name in LIBRARY_NAMES:
        out = model_outputs(name)
        per_material[name] = {model: delta_E_map(out["reference"], out[model]) for model in MODELS}
    return {model: error_summary({m: per_material[m][model] for m in LIBRARY_NAMES}) for model in MODELS}


def _kind_rows(rows, cpu, shader, models, split, split_costs) -> list[dict]:
    """The model kinds (and adjusted Lazanyi, the yardstick) for :func:`kinds_table`."""
    out = []
    for name, split_variant in (*KIND_SPLIT_SUM.items(), ("lazanyi_adjusted", "split_sum_lazanyi")):
        label, variant, size, _ = MODELS[name]
        out.append(
            {
                "name": name,
                "label": label,
                "bytes": size,
                "mean": rows[name]["mean"],
                "max": rows[name]["max"],
                "shader_ns_px": shader[variant] * 1e3 / (WIDTH * HEIGHT),
                "shader_ratio": models["ratio"][name],
                "cpu_ns": cpu[name],
                "split_mean": split[split_variant]["mean"] if split_variant else None,
                "split_ratio": split_costs["raw"][split_variant] if split_variant else None,
            }
        )
    return out


def _figures(rows, cpu, models, split, split_costs, reports) -> None:
    size = {m: 20 + MODELS[m][2] / 8 for m in MODELS}
    panels = [
        {
            "title": "Fresnel term, shader",
            "front": [MODELS[m][0] for m in models["shader"]],
            "xlabel": f"shader cost at {WIDTH} x {HEIGHT}, relative to adjusted Lazanyi (llvmpipe)",
            "points": {
                MODELS[m][0]: (models["ratio"][m], rows[m]["mean"], size[m]) for m in MODELS if models["ratio"][m]
            },
        },
        {
            "title": "Fresnel term, numpy",
            "front": [MODELS[m][0] for m in models["cpu"]],
            "xlabel": "CPU cost per sample (ns, numpy)",
            "points": {MODELS[m][0]: (cpu[m], rows[m]["mean"], size[m]) for m in MODELS},
        },
        {
            "title": f"split sum: directional albedo, {len(SPLIT_ETA_I)} eta_i x {len(SPLIT_ROUGHNESS)} roughness",
            "front": [SPLIT_VARIANTS[v][0] for v in split_costs["front"]],
            "xlabel": "split-sum shader cost, relative to adjusted Lazanyi's (llvmpipe)",
            "points": {SPLIT_VARIANTS[v][0]: (split_costs["raw"][v], split[v]["mean"], 30) for v in SPLIT_VARIANTS},
        },
    ]
    figure_speed_vs_error(IMAGES / "speed_vs_error.png", panels)
    if reports:
        figure_batch(IMAGES / "speed_vs_error_batch.png", reports, [*MODEL_KINDS, "lazanyi_adjusted"])


def main() -> None:
    parser = argparse.ArgumentParser(description="Speed against error for the 22 conductors.")
    parser.add_argument(
        "--batch-report",
        type=Path,
        metavar="REPORT_JSON",
        action="append",
        default=[],
        help="add the accuracy summary of a python -m fitting batch report.json (repeatable)",
    )
    parser.add_argument("--batch-only", action="store_true", help="print only the batch summaries")
    parser.add_argument("--figure", action="store_true", help="write the PNGs to docs/images/")
    parser.add_argument("--repeats", type=int, default=7, help="shader timing rounds")
    parser.add_argument(
        "--models-only",
        action="store_true",
        help="the models, kinds and split-sum tables only (skip the fitting-settings sweep)",
    )
    args = parser.parse_args()
    if args.batch_only and not args.batch_report:
        parser.error("--batch-only needs --batch-report")
    reports = [read_batch_report(path) for path in args.batch_report]
    t0 = time.perf_counter()
    if args.batch_only:
        print("\n".join(run_header(sys.argv[1:])) + "\n")
        for report in reports:
            print("\n".join(batch_table(report)) + "\n")
        if args.figure:
            figure_batch(IMAGES / "speed_vs_error_batch.png", reports, [*MODEL_KINDS, "lazanyi_adjusted"])
            print("wrote docs/images/speed_vs_error_batch.png")
        return

    header = run_header(sys.argv[1:])
    rows = model_table()
    cpu = cpu_cost_ns()
    shader, renderer = shader_cost(args.repeats)
    split = split_sum_table()
    split_cpu = split_sum_cpu_ns()
    split_shader = split_sum_shader_us(args.repeats, WIDTH, HEIGHT)
    pixels = WIDTH * HEIGHT
    print("\n".join(header) + f", GL: {renderer}\n")
    lines, models = models_table(MODELS, rows, cpu, shader, pixels)
    print(
        f"## Models: {len(LIBRARY_NAMES)} conductors, {GRID} x {GRID} grid, Delta E 2000 against the 1 nm "
        "reference\n\n" + "\n".join(lines)
    )
    if FIT_FAILURES:
        print(
            f"\nDegree-0 fits refused by the fitting core ({len(FIT_FAILURES)}; the general fit "
            "collapsed to that eta_i is used instead): " + "; ".join(FIT_FAILURES)
        )
    print(
        f"\nShader wall time (us, median of {args.repeats}, {WIDTH} x {HEIGHT}): "
        + ", ".join(f"{v} {t:.0f}" for v, t in shader.items())
    )
    print("\nBytes: " + "; ".join(f"{MODELS[m][0]}: {MODELS[m][3]}" for m in MODELS))
    lines, split_costs = split_sum_table_lines(SPLIT_VARIANTS, split, split_cpu, split_shader, pixels, SPLIT_ROUGHNESS)
    print(
        f"\n## Split-sum variants: {len(LIBRARY_NAMES)} conductors x eta_i {', '.join(map(str, SPLIT_ETA_I))} "
        f"x roughness {', '.join(map(str, SPLIT_ROUGHNESS))} x {len(SPLIT_NDOTV)} NdotV, Delta E 2000 of the "
        "directional albedo against the spectral one\n\n" + "\n".join(lines)
    )
    print(
        f"\nSplit-sum pass wall time (us, median of {args.repeats}, {WIDTH} x {HEIGHT}): "
        + ", ".join(f"{v} {t:.0f}" for v, t in split_shader.items())
        + "; net: the pass with no split sum (split_sum_fixed) subtracted from both sides."
    )
    print("\n## Model kinds side by side\n")
    print("\n".join(kinds_table(_kind_rows(rows, cpu, shader, models, split, split_costs), reports)))
    for report in reports:
        print("\n" + "\n".join(batch_table(report)))
    if args.figure:
        _figures(rows, cpu, models, split, split_costs, reports)
        print("\nwrote docs/images/speed_vs_error.png" + (", docs/images/speed_vs_error_batch.png" if reports else ""))

    if args.models_only:
        print(f"\nRun time: {time.perf_counter() - t0:.0f} s; load average at the end {load_average()}")
        return
    print_fit_settings(GRID, IMAGES if args.figure else None)
    print(f"\n(total {time.perf_counter() - t0:.0f} s; load average at the end {load_average()})")


if __name__ == "__main__":
    main()
