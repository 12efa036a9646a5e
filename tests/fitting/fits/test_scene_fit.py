"""fitting.fits.scene_fit and scene_report: the degree rule, scene fits, their report."""

import json
import math

import numpy as np
import pytest
from conftest import SHOWROOM_SCENE

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.fits.metrics import ErrorMetrics
from fitting.fits.scene_fit import (
    CANDIDATES,
    GENERAL,
    choose_candidate,
    fit_scene,
    fit_scene_material,
    general_domain,
)
from fitting.fits.scene_schema import (
    EVALUATION_ETA_ROWS,
    EVALUATION_MU_SAMPLES,
    EtaSpec,
    parse_scene,
)
from fitting.models.kinds import coefficient_count, model_ACEScg
from fitting.models.pack import decode_pack, pack_from_json
from fitting.optics.library import library_material

SCENE = SHOWROOM_SCENE  # and the `showroom` fixture: its fit, once a session (tests/conftest.py)


def E(mean: float, max_: float) -> ErrorMetrics:
    """Delta E 2000 (mean, max) of one candidate, as the scene fit scores it."""
    return ErrorMetrics(mean, max_, "a test grid", layout="summary")


CC0, RGB, CC1, CC2 = CANDIDATES


class TestDefaultRule:
    """Without a budget: the cheapest candidate no worse on mean and max than every dearer one."""

    def test_a_cheaper_candidate_better_on_both_wins(self):
        errors = {CC0: E(0.30, 1.0), RGB: E(0.05, 0.2), CC1: E(0.12, 0.5), CC2: E(0.10, 0.4), GENERAL: E(0.5, 2.0)}
        assert choose_candidate(errors, None, None)[0] == RGB

    def test_a_dearer_candidate_better_on_the_max_is_not_passed_over(self):
        errors = {CC0: E(0.30, 1.0), RGB: E(0.05, 0.5), CC1: E(0.06, 0.4), CC2: E(0.07, 0.45), GENERAL: E(0.5, 2.0)}
        chosen, why = choose_candidate(errors, None, None)
        assert chosen == CC1 and "no worse on mean and max than every dearer one" in why

    def test_never_worse_than_the_general_fit(self):
        errors = {CC0: E(0.04, 0.2), RGB: E(0.02, 0.3), CC1: E(0.02, 0.1), GENERAL: E(0.03, 0.1)}
        assert choose_candidate(errors, None, None)[0] == CC1
        errors[CC1] = E(0.02, 0.11)
        chosen, why = choose_candidate(errors, None, None)
        assert chosen == GENERAL and "worse than the general fit on mean or max" in why

    def test_the_choice_dominates_every_dearer_candidate(self):
        rng = np.random.default_rng(7)
        for _ in range(200):
            errors = {c: E(*sorted(rng.uniform(0.01, 2.0, 2))) for c in (*CANDIDATES, GENERAL)}
            chosen, _ = choose_candidate(errors, None, None)
            order = [*CANDIDATES, GENERAL]
            assert errors[chosen].mean <= errors[GENERAL].mean
            assert errors[chosen].max <= errors[GENERAL].max
            for dearer in order[order.index(chosen) + 1 :]:
                if errors[dearer].mean <= errors[GENERAL].mean and errors[dearer].max <= errors[GENERAL].max:
                    assert errors[chosen].mean <= errors[dearer].mean
                    assert errors[chosen].max <= errors[dearer].max


class TestFitScene:
    def test_degrees_follow_the_eta_i(self, showroom):
        by_name = {m.packed.name: m for m in showroom.materials}
        assert set(by_name["Au"].by_degree) == {0} and by_name["Au"].degree == 0
        assert by_name["trim"].degree == 0
        assert by_name["Cu"].degree <= 1
        assert set(by_name["Cu"].by_degree) == {0, 1}
        assert set(by_name["Al"].by_degree) == {0, 1, 2}
        assert by_name["Au"].packed.eta_i_range == (1.0, 1.0)
        assert by_name["Cu"].packed.eta_i_range == pytest.approx((1.33, 1.5), rel=2.0**-24)  # the
        # pack stores the range in float32: within u32 = 2^-24 relative (tightened
        # from approx's default rel=1e-6)

    def test_general_fit_covers_the_scene(self, showroom):
        trim = next(m for m in showroom.materials if m.packed.name == "trim")
        assert trim.general.eta_i_range == (1.0, pytest.approx(2.8, rel=2.0**-24))  # float32, as above
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
            assert m["delta_E_2000"]["max"] <= m["general"]["delta_E_2000"]["max"]
        single = [m for m in report["materials"] if m["coefficients"] == 9]
        for m in single:
            assert m["bytes"] == m["general"]["bytes"] - 36
            assert m["delta_E_2000"]["mean"] < m["general"]["delta_E_2000"]["mean"]

    def test_reported_error_matches_an_independent_evaluation(self, showroom):
        decoded = {m.name: m for m in decode_pack(showroom.pack_bytes())}
        for result in showroom.materials:
            spec = result.material.eta_i
            rows = np.array(spec.values) if spec.kind != "range" else np.linspace(*spec.values, EVALUATION_ETA_ROWS)
            mu = np.linspace(0.0, 1.0, EVALUATION_MU_SAMPLES)
            E, M = np.meshgrid(rows, mu, indexing="ij")
            ref = reference_ACEScg(result.material.nk, M, E)
            packed = decoded[result.packed.name]
            dE = delta_E_map(ref, model_ACEScg(packed.model, M, E, packed.coefficients, packed.eta_i_range))
            # The same reference and model on the same grid; only the
            # wavelength sum's order may differ (F64_RGB_BOUND 1.3e-13) times
            # Delta E's slope (<= ~1e3 per unit RGB at these reflectances):
            # 1.3e-10 against Delta E means >= 0.1: rel 1e-9.
            assert result.scene.mean == pytest.approx(dE.mean(), rel=1e-9)
            assert result.scene.max == pytest.approx(dE.max(), rel=1e-9)

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
            assert m["coefficients"] == coefficient_count(m["model"], m["degree"])
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
        scene = parse_scene(
            {
                "materials": [
                    {
                        "name": "red end",
                        "eta_i": 1.5,
                        "nk": {
                            "wavelength_nm": Au.wavelength_nm[keep].tolist(),
                            "n": Au.n[keep].tolist(),
                            "k": Au.k[keep].tolist(),
                        },
                    }
                ]
            }
        )
        with pytest.raises(ValueError, match=r"material 'red end': `wavelength_nm` must cover at least 90%"):
            fit_scene(scene)
