"""
Fit numbers held fixed across refactors (one model-kind registry, one pipeline):
``python -m fitting fit Au --json`` and ``... --model rgb-conductor --json``
give the float16 coefficients they gave before it, bit for bit
(``tests/golden/fit_Au_coefficients.json``, recorded on main 51b944e).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fitting.fits.kinds import fit_model
from fitting.models.pack import material_to_json
from fitting.optics.library import library_material

GOLDEN = json.loads((Path(__file__).parents[2] / "golden" / "fit_Au_coefficients.json").read_text())


@pytest.mark.slow  # two fits of Au: over 2 s on a busy machine
@pytest.mark.parametrize("model", sorted(GOLDEN["fits"]["Au"]))
def test_au_coefficients_are_the_recorded_ones(model):
    expected = GOLDEN["fits"]["Au"][model]
    view = material_to_json(fit_model(library_material("Au"), model=model).packed)
    assert view["eta_i_range"] == expected["eta_i_range"]
    assert view.get("degree", 0) == expected["degree"]
    # Exact: the same float16 values (as JSON numbers, exact binary fractions).
    assert view["coefficients"] == expected["coefficients"]
