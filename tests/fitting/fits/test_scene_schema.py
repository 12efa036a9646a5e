"""fitting.fits.scene_schema: scene descriptions."""

import json
import pytest
from conftest import SHOWROOM_SCENE

from fitting.fits.scene_schema import (
    EVALUATION_ETA_ROWS,
    MAX_ETA_I_VALUES,
    MAX_SCENE_MATERIALS,
    EtaSpec,
    parse_eta_i,
    parse_scene,
)
from fitting.optics.library import library_material

SCENE = SHOWROOM_SCENE  # and the `showroom` fixture: its fit, once a session (tests/conftest.py)


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
        scene = parse_scene(
            {
                "materials": [
                    {
                        "name": "my gold",
                        "eta_i": 1.5,
                        "nk": {
                            "wavelength_nm": Au.wavelength_nm.tolist(),
                            "n": Au.n.tolist(),
                            "k": Au.k.tolist(),
                            "source": "Johnson and Christy",
                        },
                    }
                ]
            }
        )
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
            (
                {"materials": [{"material": "Unobtainium", "eta_i": 1}]},
                r"`materials\[0\].material`: `material` must name a conductor of the library",
            ),
            ({"materials": [{"material": 3, "eta_i": 1}]}, r"`materials\[0\].material` must be"),
            ({"materials": [{"eta_i": 1}]}, "exactly one of `material` and `nk`"),
            ({"materials": [{"material": "Au", "nk": {}, "eta_i": 1}]}, "exactly one of"),
            ({"materials": [{"material": "Au", "eta_i": 1, "degree": 2}]}, "unknown keys"),
            (
                {"materials": [{"material": "Au", "eta_i": 1}, {"material": "Au", "eta_i": 2}]},
                r"`materials\[1\].name` 'Au' is used twice",
            ),
            (
                {"materials": [{"nk": {"wavelength_nm": [400, 700], "n": [1, 1], "k": [0, 0]}, "eta_i": 1}]},
                r"`materials\[0\].name` must be .*required with `nk`",
            ),
            (
                {"materials": [{"name": "x", "nk": {"n": [1]}, "eta_i": 1}]},
                r"`materials\[0\].nk` is missing wavelength_nm, k",
            ),
            (
                {
                    "materials": [
                        {"name": "x", "eta_i": 1, "nk": {"wavelength_nm": [400, 700], "n": [1, -1], "k": [0, 0]}}
                    ]
                },
                r"`materials\[0\].nk`: `n` must be > 0, got -1 at index 1",
            ),
            (
                {"materials": [{"material": "Au", "eta_i": [1, 0.5]}]},
                r"`materials\[0\].eta_i\[1\]` must lie in \[1, 3\]",
            ),
        ],
    )
    def test_refusals_name_the_field_and_rule(self, data, message):
        with pytest.raises(ValueError, match=message):
            parse_scene(data)

    def test_too_many_materials(self):
        entries = [{"material": "Au", "name": f"m{i}", "eta_i": 1.0} for i in range(MAX_SCENE_MATERIALS + 1)]
        with pytest.raises(ValueError, match=f"at most {MAX_SCENE_MATERIALS} entries"):
            parse_scene({"materials": entries})
