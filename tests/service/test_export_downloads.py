"""``GET /api/v1/fits/{id}/pack?format=mtlx|openpbr|blender|gltf&eta_i=...``."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import app_client
from fitting.fits.curves_base import curve_base_from_nk
from fitting.exports import export_material
from fitting.models.pack import pack_from_json
from fitting.optics.library import library_material

API = "/api/v1"


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("exports"), metrics_samples=30) as client:
        response = client.post(f"{API}/fits", json={"material": "Cu"})
        assert response.status_code == 201, response.text
        yield client, response.json()["id"]


def pack(client, fit_id, query):
    return client.get(f"{API}/fits/{fit_id}/pack?{query}")


def stored_model(client, fit_id):
    """The stored fit's float16 model (its JSON pack), which the export carries (glTF)."""
    return pack_from_json(pack(client, fit_id, "format=json").text)[0]


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestExportDownloads:
    @pytest.mark.slow  # 2.7 s (all cases 2.8 s) in a --durations=0 run
    @pytest.mark.parametrize(
        "format, media_type, suffix",
        [
            ("mtlx", "application/xml", ".mtlx"),
            ("openpbr", "application/xml", ".openpbr.mtlx"),
            ("blender", "text/x-python; charset=utf-8", ".py"),
            ("gltf", "model/gltf+json", ".gltf"),
        ],
    )
    def test_each_format_is_the_library_export(self, shared, format, media_type, suffix):
        client, fit_id = shared
        response = pack(client, fit_id, f"format={format}&eta_i=1.7")
        assert response.status_code == 200, response.text
        assert response.headers["content-type"] == media_type
        assert response.headers["content-disposition"] == (
            f'attachment; filename="Cu-{fit_id[:8]}-eta1.7-rough0.2-coat0.03{suffix}"'
        )
        expected = export_material(
            library_material("Cu"), format, 1.7, model=stored_model(client, fit_id), fit_id=fit_id
        )
        assert response.content == expected
        assert (b"EXT_materials_coated_conductor" in response.content) == (format == "gltf")

    @pytest.mark.slow  # starts a process or GL context
    def test_working_space_and_identity(self, shared):
        client, fit_id = shared
        response = pack(client, fit_id, "format=mtlx&eta_i=1.5&working_space=acescg")
        assert response.status_code == 200, response.text
        assert response.headers["content-disposition"] == (
            f'attachment; filename="Cu-{fit_id[:8]}-eta1.5-rough0.2-coat0.03-acescg.mtlx"'
        )
        root = ET.fromstring(response.content)
        assert root.get("colorspace") == "acescg" and root.get("coatedfresnel_fit_id") == fit_id
        assert root.find("nodedef").get("name") == f"ND_coated_metal_Cu_{fit_id[:8]}_eta1p5"

    @pytest.mark.slow  # starts a process or GL context
    def test_default_eta_i_is_1_5(self, shared):
        client, fit_id = shared
        root = ET.fromstring(pack(client, fit_id, "format=openpbr").content)
        (coat_ior,) = [e for e in root.iter("input") if e.get("name") == "coat_ior"]
        assert coat_ior.get("value") == "1.5"

    @pytest.mark.slow  # starts a process or GL context
    def test_preview_roughness_and_coat_roughness(self, shared):
        # The editor's preview values travel into the export and its file name.
        client, fit_id = shared
        response = pack(client, fit_id, "format=openpbr&eta_i=1.33&roughness=0.45&coat_roughness=0.1")
        assert response.status_code == 200, response.text
        assert response.headers["content-disposition"] == (
            f'attachment; filename="Cu-{fit_id[:8]}-eta1.33-rough0.45-coat0.1.openpbr.mtlx"'
        )
        expected = export_material(
            library_material("Cu"), "openpbr", 1.33, 0.45, 0.1, model=stored_model(client, fit_id), fit_id=fit_id
        )
        assert response.content == expected
        assert response.content != pack(client, fit_id, "format=openpbr&eta_i=1.33").content
        for query in ("roughness=1.5", "coat_roughness=-0.1", "roughness=nan", "working_space=srgb"):
            refused = pack(client, fit_id, f"format=gltf&{query}")
            assert refused.status_code == 422 and query.split("=")[0] in refused.json()["detail"]

    @pytest.mark.slow  # starts a process or GL context
    @pytest.mark.parametrize(
        "query, words",
        [
            ("format=mtlx&eta_i=0.8", ["eta_i", "greater than or equal to 1"]),
            ("format=gltf&eta_i=3.5", ["eta_i", "less than or equal to 3"]),
            ("format=blender&eta_i=nan", ["eta_i", "finite"]),
            ("format=mtlx&eta_i=abc", ["eta_i", "number"]),
            ("format=usd&eta_i=1.5", ["format", "'mtlx'", "'gltf'"]),
        ],
    )
    def test_bad_query_422(self, shared, query, words):
        client, fit_id = shared
        response = pack(client, fit_id, query)
        assert response.status_code == 422, response.text
        detail = response.json()["detail"]
        assert all(word in detail for word in words), detail

    def test_unknown_fit_404(self, shared):
        client, _ = shared
        assert pack(client, "0" * 32, "format=mtlx").status_code == 404

    def test_old_formats_unchanged(self, shared):
        client, fit_id = shared
        response = pack(client, fit_id, "format=json&eta_i=2")
        assert response.status_code == 200 and response.json()["format"]


@pytest.fixture(scope="module")
def curve_fit(shared):
    client, _ = shared
    angle = np.linspace(0.0, 90.0, 31)
    mu = np.where(angle == 90.0, 0.0, np.cos(np.radians(angle)))
    curves = []
    for eta_i in (1.3, 1.9):
        rgb = np.clip(curve_base_from_nk(library_material("Cu")).rgb(mu, eta_i), 0, 1)
        rgb[:, 2] *= 0.8
        curves.append({"eta_i": eta_i, "angle_deg": angle.tolist(), "rgb": rgb.tolist()})
    response = client.post(f"{API}/fits/from-curves", json={"name": "edited copper", "curves": curves})
    assert response.status_code == 201, response.text
    return response.json()


class TestCurveFitExports:
    def test_export_from_the_model_curve(self, shared, curve_fit):
        client, _ = shared
        response = pack(client, curve_fit["id"], "format=gltf&eta_i=1.5")
        assert response.status_code == 200, response.text
        provenance = json.loads(response.content)["materials"][0]["extras"]["coated_fresnel"]
        assert "edited curves" in provenance["fitted_to"] and provenance["eta_i"] == 1.5

    def test_outside_the_fit_domain_422(self, shared, curve_fit):
        client, _ = shared
        lo, hi = curve_fit["eta_i_range"]
        response = pack(client, curve_fit["id"], f"format=mtlx&eta_i={hi + 0.3:g}")
        assert response.status_code == 422
        assert "`eta_i` must lie in the fit's domain" in response.json()["detail"]


@pytest.fixture(scope="module")
def two_fits(shared):
    client, cu = shared
    response = client.post(f"{API}/fits", json={"material": "Au"})
    assert response.status_code == 201, response.text
    return client, [cu, response.json()["id"]]


class TestExportPacks:
    """``POST /api/v1/packs`` with an export format: a zip of one export per fit."""

    @pytest.mark.parametrize("format, suffix", [("mtlx", ".mtlx"), ("gltf", ".gltf")])
    def test_zip_holds_each_fits_export_in_order(self, two_fits, format, suffix):
        import io
        import zipfile

        client, ids = two_fits
        body = {"fit_ids": ids, "format": format, "eta_i": 1.3, "name": "scene"}
        response = client.post(f"{API}/packs", json=body)
        assert response.status_code == 200, response.text
        assert response.headers["content-type"] == "application/zip"
        assert response.headers["content-disposition"] == (f'attachment; filename="scene-{format}-eta1.3.zip"')
        archive = zipfile.ZipFile(io.BytesIO(response.content))
        assert archive.namelist() == [f"Cu-eta1.3{suffix}", f"Au-eta1.3{suffix}"]
        for name, material, fit_id in zip(archive.namelist(), ("Cu", "Au"), ids):
            model = stored_model(client, fit_id)
            assert archive.read(name) == export_material(
                library_material(material), format, 1.3, model=model, fit_id=fit_id
            )
        # Deterministic: the same request, the same bytes.
        assert client.post(f"{API}/packs", json=body).content == response.content

    def test_zip_takes_the_roughness_and_working_space(self, two_fits):
        import io
        import zipfile

        client, ids = two_fits
        body = {
            "fit_ids": ids[:1],
            "format": "openpbr",
            "eta_i": 1.3,
            "roughness": 0.45,
            "coat_roughness": 0.1,
            "working_space": "acescg",
        }
        response = client.post(f"{API}/packs", json=body)
        assert response.status_code == 200, response.text
        (entry,) = zipfile.ZipFile(io.BytesIO(response.content)).namelist()
        assert zipfile.ZipFile(io.BytesIO(response.content)).read(entry) == export_material(
            library_material("Cu"),
            "openpbr",
            1.3,
            0.45,
            0.1,
            model=stored_model(client, ids[0]),
            fit_id=ids[0],
            working_space="acescg",
        )

    @pytest.mark.parametrize(
        "body, words",
        [
            ({"format": "mtlx", "eta_i": 0.5}, ["eta_i", "greater than or equal to 1"]),
            ({"format": "mtlx", "working_space": "srgb"}, ["working_space", "'acescg'"]),
            ({"format": "mtlx", "roughness": 2}, ["roughness", "less than or equal to 1"]),
            ({"format": "usdz"}, ["format", "'mtlx'"]),
            ({"format": "gltf", "eta_i": True}, ["eta_i"]),
        ],
    )
    def test_bad_export_pack_422(self, two_fits, body, words):
        client, ids = two_fits
        response = client.post(f"{API}/packs", json={"fit_ids": ids, **body})
        assert response.status_code == 422, response.text
        detail = json.dumps(response.json())
        for word in words:
            assert word in detail

    def test_too_many_fits_for_an_export_pack_422(self, two_fits):
        client, ids = two_fits
        response = client.post(f"{API}/packs", json={"fit_ids": ids * 9, "format": "blender"})
        assert response.status_code == 422, response.text
        assert "at most 16 fits for an export pack" in response.json()["detail"]


@pytest.mark.slow
class TestExportPackNames:
    """Names that make one file name, and long names with one prefix."""

    NAMES = ["gold alloy", "gold_alloy", "gold/alloy", "Gold Alloy", "p" * 90 + "one", "p" * 90 + "two"]

    def test_every_material_has_its_own_entry(self, shared):
        import io
        import zipfile

        client, _ = shared
        wavelength = [350.0, 450.0, 550.0, 650.0, 750.0, 850.0]  # no gap over the 120 nm limit
        ids = []
        for i, name in enumerate(self.NAMES):
            nk = {"wavelength_nm": wavelength, "n": [0.2 + 0.01 * i] * 6, "k": [3.0, 3.1, 3.2, 3.3, 3.4, 3.6]}
            response = client.post(f"{API}/fits", json={"name": name, "nk": nk})
            assert response.status_code == 201, response.text
            ids.append(response.json()["id"])
        response = client.post(f"{API}/packs", json={"fit_ids": ids, "format": "mtlx", "eta_i": 1.5})
        assert response.status_code == 200, response.text
        names = zipfile.ZipFile(io.BytesIO(response.content)).namelist()
        assert len(names) == len(self.NAMES)
        assert len({n.lower() for n in names}) == len(self.NAMES), names
        assert names[:4] == [
            "gold_alloy-eta1.5.mtlx",
            "gold_alloy-eta1.5-2.mtlx",
            "gold_alloy-eta1.5-3.mtlx",
            "Gold_Alloy-eta1.5-4.mtlx",
        ]


def test_unique_names_suffix_repeats_ignoring_case():
    from service.downloads import unique_names

    assert unique_names(["a.x", "A.x", "a.x", "a-2.x", "b"]) == ["a.x", "A-2.x", "a-3.x", "a-2-2.x", "b"]


@pytest.mark.slow  # two in-process services, each with its fitting pool
def test_exports_are_jobs_of_the_fitting_pool_with_its_cpu_limit(tmp_path):
    """An export fits its tool's values (up to about a second of CPU): it runs in
    the fitting pool, under the job CPU-time limit (422 past it, the worker then
    free), never on the server's own threads; a pack of exports too."""
    with app_client(tmp_path, metrics_samples=30) as client:
        fit = client.post(f"{API}/fits", json={"material": "Cu"})
        assert fit.status_code == 201, fit.text
        fit_id = fit.json()["id"]
    with app_client(tmp_path, job_cpu_limit_s=0.05) as client:  # the same store
        refused = pack(client, fit_id, "format=mtlx&eta_i=1.5")
        assert refused.status_code == 422 and "CPU-time limit" in refused.json()["detail"], refused.text
        zipped = client.post(f"{API}/packs", json={"fit_ids": [fit_id], "format": "blender", "eta_i": 1.5})
        assert zipped.status_code == 422 and "CPU-time limit" in zipped.json()["detail"], zipped.text
        assert pack(client, fit_id, "format=json").status_code == 200  # a pack is not a job
