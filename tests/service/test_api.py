"""In-process tests of every route and status code of the HTTP service (TestClient)."""

from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM
from fitting.fits.kinds import evaluate_model, fit_model
from fitting.fits.material import fit_material
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import decode_pack, pack_from_json
from fitting.optics.library import LIBRARY_NAMES, library_material
from service.config import Settings
from service.jobs.evaluation import METRICS_DTYPE
from conftest import app_client

API = "/api/v1"


def gold_like_nk(name_shift: float = 0.0) -> dict:
    """Smooth n, k over 350-850 nm (a gold-like conductor)."""
    wavelength = np.linspace(350.0, 850.0, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2)) + name_shift
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return {"wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist()}


def csv_text(nk: dict) -> str:
    rows = [f"{w},{n},{k}" for w, n, k in zip(nk["wavelength_nm"], nk["n"], nk["k"])]
    return "wavelength_nm,n,k\n" + "\n".join(rows) + "\n"


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """One app (one worker process) for the tests that fit, with Au fitted."""
    with app_client(tmp_path_factory.mktemp("shared"), warm_pool=True, metrics_samples=30) as client:
        response = client.post(f"{API}/fits", json={"material": "Au"})
        assert response.status_code == 201, response.text
        yield client, response.json()


class TestHealthAndDocs:
    def test_healthz(self, reader):
        response = reader.get("/healthz")
        assert response.status_code == 200
        assert response.json()["status"] == "ok"
        assert response.json()["fit_workers"] == 1

    def test_healthz_503_when_store_damaged(self, client):
        client.app.state.store.close()
        response = client.get("/healthz")
        assert response.status_code == 503
        assert "store" in response.json()["detail"]

    def test_openapi_shows_constraints(self, reader):
        schema = reader.get("/openapi.json").json()
        request = schema["components"]["schemas"]["FitRequest"]["properties"]
        items = request["eta_i_range"]["prefixItems"]
        assert items[0]["minimum"] == 1.0 and items[0]["maximum"] == 3.0
        nk = schema["components"]["schemas"]["NKData"]["properties"]
        assert nk["n"]["items"]["exclusiveMinimum"] == 0.0
        assert nk["k"]["items"]["minimum"] == 0.0
        material = request["material"]["anyOf"][0]
        assert material["maxLength"] == 200 and "gold" in material["description"]
        assert reader.get("/docs").status_code == 200

    def test_domain_states_the_upload_coverage_rule(self, reader):
        domain = reader.get(f"{API}/domain").json()
        assert domain["visible_range_nm"] == list(VISIBLE_RANGE_NM)
        assert domain["min_coverage"] == DEFAULT_MIN_COVERAGE
        assert domain["draft_ttl_s"] == 86_400.0  # how long a link to an unsaved edit lasts


class TestMaterials:
    def test_library_listed_with_sources(self, reader):
        materials = reader.get(f"{API}/materials").json()["materials"]
        library = [m for m in materials if m["kind"] == "library"]
        assert set(LIBRARY_NAMES) <= {m["id"] for m in library}
        (gold,) = [m for m in library if m["id"] == "Au"]
        assert "Johnson" in gold["source"] and gold["coverage"] == pytest.approx(1.0)  # a ratio of
        # equal sums, 1 to a few u64; approx's default rel=1e-6 is loose but harmless
        assert gold["latest_fit_id"] is None

    def test_library_material_detail(self, reader):
        detail = reader.get(f"{API}/materials/Cu").json()
        assert detail["kind"] == "library" and detail["latest_fit"] is None
        low, high = detail["wavelength_range_nm"]
        assert low <= 360 and high >= 830

    def test_unknown_material_404(self, reader):
        response = reader.get(f"{API}/materials/{'ab' * 16}")
        assert response.status_code == 404
        assert "material_id" in response.json()["detail"]

    @pytest.mark.parametrize(
        "bad, code",
        [
            # The client resolves the encoded "../..": no route matches.
            ("..%2F..%2Fetc%2Fpasswd", 404),
            # A catalogue page's form (BOOK.PAGE): looked up in the catalogue and the store only.
            ("store.sqlite3", 404),
            # The id pattern refuses the rest before any lookup.
            (".sqlite3", 422),
            ("a.b.c", 422),
            ("A" * 9, 422),
        ],
    )
    def test_bad_material_id_never_reaches_files(self, reader, bad, code):
        response = reader.get(f"{API}/materials/{bad}")
        assert response.status_code == code
        if code == 422:
            assert "`material_id`" in response.json()["detail"]


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestFits:
    @pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
    def test_library_fit_is_the_core_fit(self, shared):
        client, fit = shared
        assert fit["name"] == "Au" and fit["kind"] == "library" and fit["degree"] == 2
        assert fit["eta_i_range"] == [1.0, 2.5] and fit["colour_space"] == "ACEScg"
        expected = fit_material(library_material("Au"), (1.0, 2.5)).coefficients_float16
        got = np.array([fit["coefficients"][p] for p in ("F0", "a", "alpha")])
        np.testing.assert_array_equal(got, expected.astype(np.float64))
        # The answer carries what the solve measured; the evaluation on the metrics grid comes after it.
        lazy = fit["metrics"]
        assert lazy["evaluated"] is False and lazy["figure"] is None and lazy["model"] is None
        assert lazy["details"]["guard"]["chosen"] in lazy["details"]["guard"]["candidates"]
        assert {"reference", "fit", "quantise", "total"} <= set(fit["timings"])
        assert fit["convergence"]["success"] is True
        # Asked for, the fit has them (evaluated now or in the background meanwhile).
        metrics = client.get(f"{API}/fits/{fit['id']}").json()["metrics"]
        assert metrics["evaluated"] is True and metrics["grid"] == "30x30"
        assert 0 < metrics["model"]["delta_E_mean"] < metrics["lazanyi_adjusted"]["delta_E_mean"]
        assert metrics["model"]["delta_E_mean"] <= metrics["model"]["delta_E_max"]
        assert metrics["details"]["guard"] == lazy["details"]["guard"]

    @pytest.mark.slow  # starts a process or GL context
    def test_metrics_are_the_core_evaluation(self, shared):
        # The fit in one part, its evaluation in another (asked for by the GET), stored:
        # the numbers of the core's evaluation on the service's reference, and the
        # core's quality report and guard.
        client, fit = shared
        assert client.get(f"{API}/fits/{fit['id']}").status_code == 200
        record = client.app.state.store.get_fit(fit["id"])
        nk = library_material("Au")
        result = fit_model(nk, (1.0, 2.5))
        expected = evaluate_model(nk, result, samples=30, dtype=METRICS_DTYPE)
        assert {k: v for k, v in record.metrics.items() if k not in ("quality", "guard")} == {
            k: v for k, v in expected.items() if k != "quality"
        }
        assert json.loads(json.dumps([result.quality, result.guard])) == [
            record.metrics["quality"],
            record.metrics["guard"],
        ]

    @pytest.mark.slow  # starts a process or GL context
    def test_same_input_same_id_no_refit(self, shared):
        client, fit = shared
        runner = client.app.state.runner
        before = runner.completed
        again = client.post(f"{API}/fits", json={"material": "Au", "eta_i_range": [1, 2.5]})
        assert again.status_code == 200
        assert again.json()["id"] == fit["id"]
        assert again.headers["location"] == f"{API}/fits/{fit['id']}"
        assert runner.completed == before

    def test_get_fit(self, shared):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}")
        assert response.status_code == 200 and response.json()["id"] == fit["id"]
        detail = client.get(f"{API}/materials/Au").json()
        assert detail["latest_fit"]["id"] == fit["id"]

    def test_unknown_fit_404_bad_id_422(self, shared):
        client, _ = shared
        assert client.get(f"{API}/fits/{'0' * 32}").status_code == 404
        response = client.get(f"{API}/fits/..%2Fstore.sqlite3")
        assert response.status_code == 404  # "../" resolved: no route, no file
        response = client.get(f"{API}/fits/ABCDEF")
        assert response.status_code == 422 and "fit_id" in response.json()["detail"]

    def test_inline_fit_is_a_saved_material(self, shared):
        client, _ = shared
        body = {
            "name": "my gold",
            "source": "lab 2024",
            "nk": gold_like_nk(),
            "eta_i_range": [1.2, 1.8],
            "objective": "rgb",
        }
        response = client.post(f"{API}/fits", json=body)
        assert response.status_code == 201, response.text
        fit = response.json()
        assert fit["kind"] == "nk" and fit["name"] == "my gold" and fit["source"] == "lab 2024"
        # The pack keeps the range in float32 (u32 = 6e-8 relative): approx's
        # default rel=1e-6 covers it 17x.
        assert fit["eta_i_range"] == pytest.approx([1.2, 1.8]) and fit["objective"] == "rgb" and fit["has_nk"]
        # Uploads are listed apart from the artist's saved edits (`?kind=nk`).
        default = client.get(f"{API}/materials").json()["materials"]
        assert fit["material_id"] not in [m["id"] for m in default]
        saved = client.get(f"{API}/materials", params={"kind": "nk"}).json()["materials"]
        assert fit["material_id"] in [m["id"] for m in saved]
        detail = client.get(f"{API}/materials/{fit['material_id']}").json()
        assert detail["latest_fit"]["id"] == fit["id"] and detail["name"] == "my gold"

    @pytest.mark.parametrize("suffix", ["csv", "json", "yaml"])
    def test_upload_formats(self, shared, suffix):
        client, _ = shared
        nk = gold_like_nk(0.01 * len(suffix))
        if suffix == "csv":
            content = csv_text(nk)
        elif suffix == "json":
            content = json.dumps(nk)
        else:
            rows = "\n".join(f"      {w / 1000} {n} {k}" for w, n, k in zip(nk["wavelength_nm"], nk["n"], nk["k"]))
            content = f"REFERENCES: test data\nDATA:\n  - type: tabulated nk\n    data: |\n{rows}\n"
        response = client.post(
            f"{API}/fits/upload",
            files={"file": (f"metal.{suffix}", content)},
            data={"eta_i_min": "1.0", "eta_i_max": "2.0"},
        )
        assert response.status_code == 201, response.text
        fit = response.json()
        assert fit["name"] == "metal" and fit["eta_i_range"] == [1.0, 2.0]
        again = client.post(
            f"{API}/fits/upload",
            files={"file": (f"metal.{suffix}", content)},
            data={"eta_i_min": "1.0", "eta_i_max": "2.0"},
        )
        assert again.status_code == 200 and again.json()["id"] == fit["id"]

    @pytest.mark.parametrize(
        ("file_name", "content", "form", "needle"),
        [
            ("bad.csv", "wavelength_nm,n,k\n400,1,x\n", {}, "CSV line 2"),
            ("bad.csv", "", {}, "CSV is empty"),
            ("bad.csv", "\r\U00100000:/1", {}, "CSV is malformed"),
            ("bad.yaml", "DATA: [\n", {}, "YAML is not valid"),
            ("bad.json", "{", {}, "JSON is not valid"),
            ("bad.exe", "MZ", {}, "`format`"),
            ("ok.csv", "wavelength_nm,n,k\n400,1,1\n500,1,1\n", {}, "cover at least"),
            ("ok.csv", "wavelength_nm,n,k\n400,1,1\n", {"format": "pdf"}, "format"),
            ("ok.csv", "x", {"eta_i_min": "2", "eta_i_max": "1.5"}, "eta_i_range"),
            ("ok.csv", "x", {"eta_i_min": "0.5"}, "eta_i_min"),
        ],
    )
    def test_upload_bad_files_422(self, reader, file_name, content, form, needle):
        response = reader.post(f"{API}/fits/upload", files={"file": (file_name, content)}, data=form)
        assert response.status_code == 422, response.text
        assert needle in response.json()["detail"]

    def test_upload_broken_multipart_422(self, reader):
        response = reader.post(
            f"{API}/fits/upload",
            content=b'--x\r\nContent-Disposition: form-data; name="file"',
            headers={"content-type": "multipart/form-data; boundary=x"},
        )
        assert response.status_code == 422, response.text
        assert "`file` (body): Field required" in response.json()["detail"]

    def test_upload_too_large_413(self, tmp_path):
        with app_client(tmp_path, max_upload_bytes=2000) as client:
            response = client.post(
                f"{API}/fits/upload", files={"file": ("big.csv", "wavelength_nm,n,k\n" + "1,1,1\n" * 1000)}
            )
            assert response.status_code == 413
            assert "COATED_MAX_UPLOAD_BYTES" in response.json()["detail"]

    def test_body_too_large_413(self, tmp_path):
        with app_client(tmp_path, max_body_bytes=5000) as client:
            nk = {"wavelength_nm": list(range(1, 2000)), "n": [1.0] * 1999, "k": [1.0] * 1999}
            response = client.post(f"{API}/fits", json={"name": "x", "nk": nk})
            assert response.status_code == 413
            assert "COATED_MAX_BODY_BYTES" in response.json()["detail"]


def nk_body(**changes) -> dict:
    nk = gold_like_nk()
    nk.update(changes)
    return {"name": "bad", "nk": nk}


class TestBadInput:
    @pytest.mark.parametrize(
        ("body", "needle"),
        [
            (b'{"material": "Au"', "valid JSON"),
            (b'{"material": NaN}', "material"),
            (b'{"material": "Au", "eta_i_range": [1, Infinity]}', "eta_i_range[1]"),
            (b"[1, 2]", "dictionary"),
            (b'\xe75\xbd\x91{"material": "Au"}', "must be UTF-8"),
            (b"[" * 100_000 + b"]" * 100_000, "nested at most"),
            (b'{"material": 3}', "material"),
            (b'{"material": "Unobtainium"}', "material"),
            (b"{}", "exactly one of"),
            (b'{"material": "Au", "nk": {"wavelength_nm": [1, 2], "n": [1, 1], "k": [0, 0]}}', "exactly one"),
            (b'{"material": "Au", "colour": "red"}', "colour"),
            (b'{"material": "Au", "objective": "l1"}', "objective"),
            (b'{"material": "Au", "eta_i_range": [0.9, 2]}', "eta_i_range[0]"),
            (b'{"material": "Au", "eta_i_range": [1.5, 3.5]}', "eta_i_range[1]"),
            (b'{"material": "Au", "eta_i_range": [2.0, 1.5]}', "must not be empty"),
            (b'{"material": "Au", "eta_i_range": []}', "eta_i_range"),
            (b'{"material": "Au", "eta_i_range": "1-2"}', "eta_i_range"),
        ],
    )
    def test_bad_json_422(self, reader, body, needle):
        response = reader.post(f"{API}/fits", content=body, headers={"content-type": "application/json"})
        assert response.status_code == 422, response.text
        assert needle in response.json()["detail"]

    @pytest.mark.parametrize(
        ("body", "needle"),
        [
            (nk_body(n=[0.0] + gold_like_nk()["n"][1:]), "`nk.n[0]` (body): Input should be greater than 0"),
            (nk_body(n=[-1.0] + gold_like_nk()["n"][1:]), "nk.n[0]"),
            (
                nk_body(k=[-0.1] + gold_like_nk()["k"][1:]),
                "`nk.k[0]` (body): Input should be greater than or equal to 0",
            ),
            (nk_body(wavelength_nm=gold_like_nk()["wavelength_nm"][::-1]), "strictly increasing (unsorted)"),
            (nk_body(wavelength_nm=[350.0, 350.0] + gold_like_nk()["wavelength_nm"][2:]), "(duplicate)"),
            ({"name": "x", "nk": {"wavelength_nm": [500.0], "n": [1.0], "k": [1.0]}}, "at least 2 items"),
            (nk_body(n=[1.0, 1.0]), "`n` must have one value per wavelength"),
            (
                {"name": "x", "nk": {"wavelength_nm": [400.0, 500.0], "n": [1, 1], "k": [1, 1]}},
                "must cover at least 90% of 360-830 nm",
            ),
            ({"name": " ", "nk": gold_like_nk()}, "name"),
            (nk_body(wavelength_nm=["a"] * 26), "wavelength_nm[0]"),
        ],
    )
    def test_bad_nk_422(self, reader, body, needle):
        response = reader.post(f"{API}/fits", json=body)
        assert response.status_code == 422, response.text
        assert needle in response.json()["detail"]

    def test_nan_inside_nk_422(self, reader):
        body = json.dumps(nk_body()).replace('"k": [1.8', '"k": [NaN')
        response = reader.post(f"{API}/fits", content=body, headers={"content-type": "application/json"})
        assert response.status_code == 422
        assert "`nk.k[0]` (body): Input should be a finite number" in response.json()["detail"]


class TestPacks:
    def test_binary_pack_decodes_to_the_fit(self, shared):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/pack")
        assert response.status_code == 200
        assert response.headers["content-type"] == "application/octet-stream"
        assert response.headers["content-disposition"] == f'attachment; filename="Au-{fit["id"][:8]}.cfpk"'
        (material,) = decode_pack(response.content)
        got = np.array([fit["coefficients"][p] for p in ("F0", "a", "alpha")])
        np.testing.assert_array_equal(material.coefficients.astype(np.float64), got)
        assert material.name == "Au" and material.eta_i_range == (1.0, 2.5)

    def test_json_pack(self, shared):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/pack", params={"format": "json"})
        (material,) = pack_from_json(response.content)
        assert material.metrics["fit_id"] == fit["id"]
        assert response.headers["content-disposition"].endswith('.json"')

    @pytest.mark.parametrize("language", ["glsl", "hlsl"])
    def test_snippets_carry_coefficients_and_function(self, shared, language):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/pack", params={"format": language})
        assert response.status_code == 200
        assert response.headers["content-type"].startswith("text/plain")
        text = response.text
        assert "cf_material_Au(float NdotV, float eta_i)" in text
        assert repr(fit["coefficients"]["alpha"][0][0]) in text
        assert fit["id"] in text

    def test_unknown_format_422(self, shared):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/pack", params={"format": "fbx"})
        assert response.status_code == 422 and "format" in response.json()["detail"]

    def test_pack_of_unknown_fit_404(self, reader):
        assert reader.get(f"{API}/fits/{'1' * 32}/pack").status_code == 404

    def test_multi_material_pack(self, shared):
        client, fit = shared
        copper = client.post(f"{API}/fits", json={"material": "Cu"}).json()
        response = client.post(f"{API}/packs", json={"fit_ids": [copper["id"], fit["id"]], "name": "scene"})
        assert response.status_code == 200
        assert response.headers["content-disposition"] == 'attachment; filename="scene.cfpk"'
        assert [m.name for m in decode_pack(response.content)] == ["Cu", "Au"]
        glsl = client.post(f"{API}/packs", json={"fit_ids": [copper["id"], fit["id"]], "format": "glsl"}).text
        assert "cf_material_Cu(" in glsl and "cf_material_Au(" in glsl

    @pytest.mark.parametrize(
        ("body", "status"),
        [
            ({"fit_ids": []}, 422),
            ({"fit_ids": ["../etc"]}, 422),
            ({"fit_ids": ["2" * 32]}, 404),
            ({"fit_ids": ["2" * 32], "format": "zip"}, 422),
            ({"fit_ids": ["2" * 32], "name": "../x"}, 422),
        ],
    )
    def test_pack_errors(self, reader, body, status):
        response = reader.post(f"{API}/packs", json=body)
        assert response.status_code == status
        assert response.json()["detail"]


class TestCurves:
    def test_curves_against_reference(self, shared):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/curves", params={"eta_i": 1.5, "samples": 19})
        assert response.status_code == 200
        curves = response.json()
        theta = np.array(curves["theta_deg"])
        assert theta[0] == 0 and theta[-1] == 90 and theta.size == 19
        mu = np.cos(np.radians(theta))
        coefficients = np.array([fit["coefficients"][p] for p in ("F0", "a", "alpha")])
        np.testing.assert_allclose(
            curves["model"],
            coated_conductor_model(np.clip(mu, 0, 1), 1.5, coefficients),
            atol=1e-12,  # the
            # same float64 kernel on JSON-exact inputs; only cos(radians) rounds
            # differently by <= 4 ulps, times the model's slope <= ~10: 5e-15
        )
        reference = np.array(curves["reference"])
        # The float64 reference by another path: within F64_RGB_BOUND (1.3e-13,
        # tests/precision.py); assert_allclose's default rtol=1e-7 holds it with room.
        np.testing.assert_allclose(reference, reference_ACEScg(library_material("Au"), np.clip(mu, 0, 1), 1.5))
        assert delta_E_map(reference, np.array(curves["model"])).mean() < 1.0
        assert np.array(curves["lazanyi_adjusted"]).shape == (19, 3)

    @pytest.mark.parametrize("params", [{"eta_i": 0.5}, {"eta_i": "nan"}, {"samples": 1}, {"samples": 5000}])
    def test_bad_query_422(self, shared, params):
        client, fit = shared
        response = client.get(f"{API}/fits/{fit['id']}/curves", params=params)
        assert response.status_code == 422
        assert next(iter(params)) in response.json()["detail"]

    def test_unknown_fit_404(self, reader):
        assert reader.get(f"{API}/fits/{'3' * 32}/curves").status_code == 404


@pytest.mark.gl
class TestPreview:
    def test_png(self, shared):
        client, fit = shared
        response = client.get(f"{API}/preview.png", params={"fit": fit["id"], "size": 64, "compare": "reference"})
        assert response.status_code == 200, response.text
        assert response.headers["content-type"] == "image/png"
        from PIL import Image
        import io

        image = Image.open(io.BytesIO(response.content))
        assert image.size == (64, 64)

    def test_a_repeated_preview_is_answered_from_memory(self, shared):
        client, fit = shared
        params = {"fit": fit["id"], "size": 64, "eta_i": 1.3}
        first = client.get(f"{API}/preview.png", params=params)
        assert first.status_code == 200, first.text
        derived = client.app.state.derived
        hits = derived.hits
        again = client.get(f"{API}/preview.png", params=params)
        assert again.content == first.content and derived.hits == hits + 1

    @pytest.mark.parametrize(
        ("params", "status"),
        [({"size": 4096}, 422), ({"size": 32}, 422), ({"compare": "x"}, 422), ({"eta_i": 5}, 422)],
    )
    def test_bad_query(self, shared, params, status):
        client, fit = shared
        response = client.get(f"{API}/preview.png", params={"fit": fit["id"], **params})
        assert response.status_code == status

    def test_unknown_fit_404(self, reader):
        assert reader.get(f"{API}/preview.png", params={"fit": "4" * 32}).status_code == 404

    def test_size_above_setting_422(self, tmp_path):
        with app_client(tmp_path, max_preview_size=128) as client:
            response = client.get(f"{API}/preview.png", params={"fit": "4" * 32, "size": 256})
            assert response.status_code == 422 and "COATED_MAX_PREVIEW_SIZE" in response.json()["detail"]


class TestLoadLimits:
    @pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
    def test_overload_503_with_retry_after(self, tmp_path):
        with app_client(tmp_path, fit_queue=0) as client:
            runner = client.app.state.runner
            first: dict = {}
            thread = threading.Thread(
                target=lambda: first.update(r=client.post(f"{API}/fits", json={"material": "Ag"}))
            )
            thread.start()
            deadline = time.monotonic() + 60
            while runner.in_flight == 0 and time.monotonic() < deadline:
                time.sleep(0.01)
            assert runner.in_flight == 1
            response = client.post(f"{API}/fits", json={"material": "Al"})
            thread.join()
            assert response.status_code == 503
            assert int(response.headers["retry-after"]) >= 1
            assert "limit" in response.json()["detail"]
            assert first["r"].status_code == 201

    @pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
    def test_timeout_504(self, tmp_path):
        with app_client(tmp_path, fit_timeout_s=0.001) as client:
            response = client.post(f"{API}/fits", json={"material": "Ni"})
            assert response.status_code == 504
            assert "time limit of 0.001 s" in response.json()["detail"]


class TestSecurity:
    def test_token_required_for_writes(self, tmp_path):
        with app_client(tmp_path, require_token=True, api_token="s3cret") as client:
            response = client.post(f"{API}/fits", json={"material": "Au"})
            assert response.status_code == 401
            assert response.headers["www-authenticate"] == "Bearer"
            wrong = client.post(f"{API}/fits", json={"material": "Au"}, headers={"Authorization": "Bearer nope"})
            assert wrong.status_code == 401
            right = client.post(f"{API}/fits", json={"material": "Nope"}, headers={"Authorization": "Bearer s3cret"})
            assert right.status_code == 422  # past the token check, refused by the schema
            upload = client.post(f"{API}/fits/upload", files={"file": ("a.csv", "x")})
            assert upload.status_code == 401
            assert client.get(f"{API}/materials").status_code == 200

    def test_token_on_by_default_off_loopback(self, tmp_path):
        with pytest.raises(ValueError, match="COATED_API_TOKEN"):
            Settings(data_dir=tmp_path, host="0.0.0.0")
        assert Settings(data_dir=tmp_path, host="0.0.0.0", api_token="t").token_required
        assert not Settings(data_dir=tmp_path, host="127.0.0.1").token_required
        assert not Settings(data_dir=tmp_path, host="0.0.0.0", require_token=False).token_required

    def test_cors_closed_by_default(self, reader):
        response = reader.get(f"{API}/materials", headers={"Origin": "https://evil.example"})
        assert "access-control-allow-origin" not in response.headers
        preflight = reader.options(
            f"{API}/fits", headers={"Origin": "https://evil.example", "Access-Control-Request-Method": "POST"}
        )
        assert "access-control-allow-origin" not in preflight.headers

    def test_cors_when_configured(self, tmp_path):
        with app_client(tmp_path, cors_origins=["https://editor.example"]) as client:
            response = client.get(f"{API}/materials", headers={"Origin": "https://editor.example"})
            assert response.headers["access-control-allow-origin"] == "https://editor.example"

    @pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
    def test_cross_site_writes_refused(self, client):
        # A multipart upload needs no CORS preflight: without this check any
        # page a user visits could plant materials in the store.
        files = {"file": ("x.csv", csv_text(gold_like_nk()), "text/csv")}
        response = client.post(f"{API}/fits/upload", files=files, headers={"Origin": "http://evil.example"})
        assert response.status_code == 403 and "cross-site writes are refused" in response.json()["detail"]
        response = client.post(f"{API}/fits", json={"material": "Au"}, headers={"Origin": "null"})
        assert response.status_code == 403
        listed = client.get(f"{API}/materials").json()["materials"]
        assert not [m for m in listed if m["kind"] != "library"]
        # The editor's own page (same origin) and pipelines (no Origin) write as before.
        same = client.post(f"{API}/fits/upload", files=files, headers={"Origin": "http://testserver"})
        assert same.status_code == 201, same.text

    @pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
    def test_configured_origin_may_write(self, tmp_path):
        with app_client(tmp_path, cors_origins=["https://editor.example"]) as client:
            response = client.post(
                f"{API}/fits/upload",
                files={"file": ("x.csv", csv_text(gold_like_nk()), "text/csv")},
                headers={"Origin": "https://editor.example"},
            )
            assert response.status_code == 201, response.text


class TestPackNames:
    def test_duplicate_names_refused(self, shared):
        client, fit = shared
        other = client.post(f"{API}/fits", json={"material": "Au", "eta_i_range": [1.0, 2.0]}).json()
        assert other["id"] != fit["id"] and other["name"] == fit["name"]
        response = client.post(f"{API}/packs", json={"fit_ids": [fit["id"], other["id"]]})
        assert response.status_code == 422
        assert "names in a pack must be unique" in response.json()["detail"]
