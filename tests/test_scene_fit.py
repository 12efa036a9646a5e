"""Scene descriptions, scene fits and their report (fitting.fits.scene_schema)."""

import json
import math

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.fits.scene_fit import (
    DEGREE_TOLERANCE_MAX,
    DEGREE_TOLERANCE_MEAN,
    choose_degree,
    fit_scene,
    fit_scene_material,
    general_domain,
)
from fitting.fits.scene_schema import (
    EVALUATION_ETA_ROWS,
    EVALUATION_MU_SAMPLES,
    MAX_ETA_I_VALUES,
    MAX_SCENE_MATERIALS,
    EtaSpec,
    parse_eta_i,
    parse_scene,
)
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import (
    PackedMaterial,
    decode_pack,
    encode_pack,
    material_record_bytes,
    pack_from_json,
)
from fitting.optics.library import library_material

SCENE = {
    "name": "showroom",
    "materials": [
        {"material": "Au", "eta_i": 1.0},
        {"material": "Cu", "eta_i": [1.5, 1.33]},
        {"material": "Al", "eta_i": {"min": 1.3, "max": 1.6}},
        {"material": "Cr", "name": "trim", "eta_i": 2.8},
    ],
}


@pytest.fixture(scope="module")
def showroom():
    return fit_scene(parse_scene(SCENE))


class TestParseEtaI:
    def test_one_value(self):
        assert parse_eta_i(1.5) == EtaSpec("one", (1.5,))
        assert parse_eta_i(1) == EtaSpec("one", (1.0,))

    def test_set_is_sorted_and_distinct(self):
        assert parse_eta_i([2.0, 1.33, 2.0]) == EtaSpec("set", (1.33, 2.0))
        assert parse_eta_i([1.5, 1.5]) == EtaSpec("one", (1.5,))

    def test_range(self):
        spec = parse_eta_i({"min": 1.2, "max": 1.8})
        assert spec == EtaSpec("range", (1.2, 1.8))
        assert spec.domain == (1.2, 1.8)
        assert spec.max_degree == 2
        assert spec.evaluation_eta_i().size == EVALUATION_ETA_ROWS
        assert parse_eta_i({"min": 1.4, "max": 1.4}) == EtaSpec("one", (1.4,))

    def test_max_degree_of_a_set_follows_its_size(self):
        assert parse_eta_i([1.0, 2.0]).max_degree == 1
        assert parse_eta_i([1.0, 1.5, 2.0, 2.5]).max_degree == 2
        assert parse_eta_i(2.0).max_degree == 0

    def test_json_view_round_trips(self):
        for value in (1.5, [1.33, 2.0], {"min": 1.0, "max": 2.5}):
            assert parse_eta_i(parse_eta_i(value).to_json()).to_json() == value

    @pytest.mark.parametrize(
        "value, message",
        [
            (0.8, r"`eta_i` must lie in \[1, 3\]"),
            (3.5, r"`eta_i` must lie in \[1, 3\]"),
            (float("nan"), r"`eta_i` must lie in \[1, 3\]"),
            (float("inf"), r"`eta_i` must lie in \[1, 3\]"),
            (True, "`eta_i` must be a number"),
            ("1.5", "`eta_i` must be a number"),
            (None, "`eta_i` must be a number"),
            ([], "at least one value"),
            ([1.5, "x"], r"`eta_i\[1\]` must be a number"),
            ([1.0] * (MAX_ETA_I_VALUES + 1), f"at most {MAX_ETA_I_VALUES} values"),
            ({"min": 2.0, "max": 1.5}, "min <= max"),
            ({"min": 1.0}, "as a range must be"),
            ({"min": 1.0, "max": 2.0, "step": 0.1}, "as a range must be"),
            ({"min": 1.0, "max": 9.0}, r"`eta_i.max` must lie in \[1, 3\]"),
        ],
    )
    def test_refusals_name_the_field_and_rule(self, value, message):
        with pytest.raises(ValueError, match=message):
            parse_eta_i(value)


class TestParseScene:
    def test_library_materials(self):
        scene = parse_scene(json.dumps(SCENE))
        assert scene.name == "showroom"
        assert [m.name for m in scene.materials] == ["Au", "Cu", "Al", "trim"]
        assert scene.materials[3].material == "Cr"
        assert scene.materials[0].nk is library_material("Au")

    def test_inline_nk(self):
        Au = library_material("Au")
        scene = parse_scene({"materials": [{
            "name": "my gold", "eta_i": 1.5,
            "nk": {"wavelength_nm": Au.wavelength_nm.tolist(), "n": Au.n.tolist(),
                   "k": Au.k.tolist(), "source": "Johnson and Christy"},
        }]})
        nk = scene.materials[0].nk
        assert nk.name == "my gold" and nk.source == "Johnson and Christy"
        assert nk.content_key() == Au.content_key()

    def test_resolver(self):
        calls = []

        def resolve(name):
            calls.append(name)
            if name != "stored-1":
                raise ValueError(f"`material_id` {name!r} is not stored")
            return library_material("Cu")

        scene = parse_scene({"materials": [{"material": "stored-1", "eta_i": 1.0}]}, resolve)
        assert calls == ["stored-1"] and scene.materials[0].nk is library_material("Cu")
        with pytest.raises(ValueError, match=r"`materials\[0\].material`: `material_id` 'x'"):
            parse_scene({"materials": [{"material": "x", "eta_i": 1.0}]}, resolve)

    @pytest.mark.parametrize(
        "data, message",
        [
            ("{", "scene is not valid JSON"),
            (b"\xff", "scene is not valid JSON"),
            ("[]", "scene must be a JSON object"),
            ({}, "`materials` must be a non-empty list"),
            ({"materials": []}, "`materials` must be a non-empty list"),
            ({"materials": {}}, "`materials` must be a non-empty list"),
            ({"materials": [{"material": "Au", "eta_i": 1}], "extra": 1}, "unknown keys"),
            ({"name": "", "materials": [{"material": "Au", "eta_i": 1}]}, "`name` must be"),
            ({"materials": [1]}, r"`materials\[0\]` must be an object"),
            ({"materials": [{"material": "Au"}]}, r"`materials\[0\].eta_i` is required"),
            ({"materials": [{"material": "Ti", "eta_i": 1}]},
             r"`materials\[0\].material`: `material` must be one of Ag"),
            ({"materials": [{"material": 3, "eta_i": 1}]}, r"`materials\[0\].material` must be"),
            ({"materials": [{"eta_i": 1}]}, "exactly one of `material` and `nk`"),
            ({"materials": [{"material": "Au", "nk": {}, "eta_i": 1}]}, "exactly one of"),
            ({"materials": [{"material": "Au", "eta_i": 1, "degree": 2}]}, "unknown keys"),
            ({"materials": [{"material": "Au", "eta_i": 1}, {"material": "Au", "eta_i": 2}]},
             r"`materials\[1\].name` 'Au' is used twice"),
            ({"materials": [{"nk": {"wavelength_nm": [400, 700], "n": [1, 1], "k": [0, 0]},
                             "eta_i": 1}]}, r"`materials\[0\].name` must be .*required with `nk`"),
            ({"materials": [{"name": "x", "nk": {"n": [1]}, "eta_i": 1}]},
             r"`materials\[0\].nk` is missing wavelength_nm, k"),
            ({"materials": [{"name": "x", "eta_i": 1,
                             "nk": {"wavelength_nm": [400, 700], "n": [1, -1], "k": [0, 0]}}]},
             r"`materials\[0\].nk`: `n` must be > 0, got -1 at index 1"),
            ({"materials": [{"material": "Au", "eta_i": [1, 0.5]}]},
             r"`materials\[0\].eta_i\[1\]` must lie in \[1, 3\]"),
        ],
    )
    def test_refusals_name_the_field_and_rule(self, data, message):
        with pytest.raises(ValueError, match=message):
            parse_scene(data)

    def test_too_many_materials(self):
        entries = [{"material": "Au", "name": f"m{i}", "eta_i": 1.0}
                   for i in range(MAX_SCENE_MATERIALS + 1)]
        with pytest.raises(ValueError, match=f"at most {MAX_SCENE_MATERIALS} entries"):
            parse_scene({"materials": entries})


class TestChooseDegree:
    def test_lowest_degree_within_tolerance(self):
        by = {0: {"mean": 0.30, "max": 1.0}, 1: {"mean": 0.12, "max": 0.5},
              2: {"mean": 0.10, "max": 0.4}}
        assert choose_degree(by, {"mean": 0.5, "max": 2.0}) == 1

    def test_tolerances_are_inclusive_bounds(self):
        by = {0: {"mean": 0.10 + DEGREE_TOLERANCE_MEAN, "max": 0.4 + DEGREE_TOLERANCE_MAX},
              1: {"mean": 0.10, "max": 0.4}}
        assert choose_degree(by, {"mean": 1.0, "max": 1.0}) == 0
        by[0]["max"] += 0.01
        assert choose_degree(by, {"mean": 1.0, "max": 1.0}) == 1

    def test_never_worse_than_the_general_fit(self):
        by = {0: {"mean": 0.04, "max": 0.2}, 1: {"mean": 0.02, "max": 0.1},
              2: {"mean": 0.01, "max": 0.1}}
        assert choose_degree(by, {"mean": 0.03, "max": 0.1}) == 1

    def test_falls_back_to_the_lowest_mean(self):
        by = {0: {"mean": 0.5, "max": 3.0}, 1: {"mean": 0.2, "max": 0.3},
              2: {"mean": 0.3, "max": 0.3}}
        assert choose_degree(by, {"mean": 0.1, "max": 0.2}) == 1


class TestRecordBytes:
    @pytest.mark.parametrize("degree", [0, 1, 2])
    def test_matches_the_binary_pack(self, degree):
        material = PackedMaterial("Gold é", np.zeros((3, 3, degree + 1), np.float16),
                                  (1.0, 2.0), source="J&C 1972")
        pack = encode_pack([material])
        header, crc = 12, 4
        assert material_record_bytes("Gold é", "J&C 1972", degree) == len(pack) - header - crc


class TestFitScene:
    def test_degrees_follow_the_eta_i(self, showroom):
        by_name = {m.packed.name: m for m in showroom.materials}
        assert by_name["Au"].degree == 0 and by_name["Au"].shader_variant == "collapsed"
        assert by_name["trim"].degree == 0
        assert by_name["Cu"].degree <= 1
        assert set(by_name["Cu"].by_degree) == {0, 1}
        assert set(by_name["Al"].by_degree) == {0, 1, 2}
        assert by_name["Au"].packed.eta_i_range == (1.0, 1.0)
        assert by_name["Cu"].packed.eta_i_range == pytest.approx((1.33, 1.5))

    def test_general_fit_covers_the_scene(self, showroom):
        trim = next(m for m in showroom.materials if m.packed.name == "trim")
        assert trim.general.eta_i_range == (1.0, pytest.approx(2.8))
        assert trim.general.degree == 2
        assert general_domain(EtaSpec("one", (1.5,))) == (1.0, 2.5)

    def test_smaller_pack_and_lower_error_than_the_general_fit(self, showroom):
        report = showroom.report()
        totals = report["totals"]
        assert totals["pack_bytes"] < totals["general_pack_bytes"]
        assert totals["coefficients"] < totals["general_coefficients"]
        assert totals["delta_E_2000_mean"] < totals["general_delta_E_2000_mean"]
        for m in report["materials"]:
            assert m["bytes"] <= m["general"]["bytes"]
            assert m["delta_E_2000"]["mean"] <= m["general"]["delta_E_2000"]["mean"]
        single = [m for m in report["materials"] if m["degree"] == 0]
        for m in single:
            assert m["bytes"] == m["general"]["bytes"] - 36
            assert m["delta_E_2000"]["mean"] < m["general"]["delta_E_2000"]["mean"]

    def test_reported_error_matches_an_independent_evaluation(self, showroom):
        decoded = {m.name: m for m in decode_pack(showroom.pack_bytes())}
        for result in showroom.materials:
            spec = result.material.eta_i
            rows = np.array(spec.values) if spec.kind != "range" else np.linspace(
                *spec.values, EVALUATION_ETA_ROWS)
            mu = np.linspace(0.0, 1.0, EVALUATION_MU_SAMPLES)
            E, M = np.meshgrid(rows, mu, indexing="ij")
            ref = reference_ACEScg(result.material.nk, M, E)
            packed = decoded[result.packed.name]
            dE = delta_E_map(ref, coated_conductor_model(M, E, packed.coefficients,
                                                         packed.eta_i_range))
            assert result.scene["mean"] == pytest.approx(dE.mean(), rel=1e-9)
            assert result.scene["max"] == pytest.approx(dE.max(), rel=1e-9)

    def test_pack_round_trips(self, showroom):
        assert decode_pack(showroom.pack_bytes()) == showroom.packed
        assert pack_from_json(showroom.pack_json()) == showroom.packed
        assert len(showroom.pack_bytes()) == showroom.report()["totals"]["pack_bytes"]

    def test_report_is_json_and_finite(self, showroom):
        text = json.dumps(showroom.report(), allow_nan=False)
        report = json.loads(text)
        assert report["scene"] == "showroom"
        assert [m["name"] for m in report["materials"]] == ["Au", "Cu", "Al", "trim"]
        for m in report["materials"]:
            assert m["coefficients"] == 9 * (m["degree"] + 1)
            assert all(math.isfinite(v) for v in m["delta_E_2000"].values())
            assert m["fit"]["success"] is True

    def test_deterministic(self, showroom):
        again = fit_scene_material(showroom.scene.materials[1])
        first = showroom.materials[1]
        assert again.packed.coefficients.tobytes() == first.packed.coefficients.tobytes()
        assert again.scene == first.scene

    def test_refusal_names_the_material(self):
        Au = library_material("Au")
        keep = (Au.wavelength_nm >= 500) & (Au.wavelength_nm <= 900)
        scene = parse_scene({"materials": [{
            "name": "red end", "eta_i": 1.5,
            "nk": {"wavelength_nm": Au.wavelength_nm[keep].tolist(),
                   "n": Au.n[keep].tolist(), "k": Au.k[keep].tolist()},
        }]})
        with pytest.raises(ValueError, match=r"material 'red end': `wavelength_nm` must cover at least 90%"):
            fit_scene(scene)
