"""``POST /api/v1/fits/import``: every pack and export of a fit back to that fit, to the bit."""

from __future__ import annotations

import base64
import json

import pytest

from conftest import app_client
from fitting.exports import export_material
from fitting.models.pack import encode_pack, pack_from_json
from fitting.optics.library import library_material

API = "/api/v1"
FORMATS = ("binary", "json", "mtlx", "openpbr", "blender", "gltf", "glb")


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("imports"), metrics_samples=30) as client:
        response = client.post(f"{API}/fits", json={"material": "Cu"})
        assert response.status_code == 201, response.text
        fit_id = response.json()["id"]
        files = {}
        for format in FORMATS:
            got = client.get(f"{API}/fits/{fit_id}/pack?format={format}&eta_i=1.5")
            assert got.status_code == 200, got.text
            files[format] = got.content
        yield client, fit_id, files


def post(client, data: bytes, name: str = "file"):
    return client.post(f"{API}/fits/import", files={"file": (name, data)})


def gltf_extras(data: bytes, **changes) -> bytes:
    """The glTF export with its material's ``extras.coated_fresnel`` changed."""
    asset = json.loads(data)
    asset["materials"][0]["extras"]["coated_fresnel"].update(changes)
    return json.dumps(asset).encode()


def model_of(client, fit_id: str):
    return pack_from_json(client.get(f"{API}/fits/{fit_id}/pack?format=json").text)[0]


@pytest.mark.slow  # the shared fixture fits and exports in the pool's processes
class TestImport:
    @pytest.mark.parametrize("format", FORMATS)
    def test_each_format_is_the_stored_fit(self, shared, format):
        client, fit_id, files = shared
        response = post(client, files[format])
        answer = response.json()
        # The same coefficients to the bit, whatever the format.
        assert model_of(client, answer["id"]) == model_of(client, fit_id)
        if format == "binary":
            # A binary pack names no fit: a new record of its model, the same one each time.
            assert response.status_code == 201 and answer["id"] != fit_id, response.text
            assert post(client, files[format]).json()["id"] == answer["id"]
            return
        assert response.status_code == 200, response.text
        assert answer["id"] == fit_id
        assert response.headers["location"] == f"{API}/fits/{fit_id}"

    def test_a_file_of_no_stored_fit_makes_one(self, shared):
        client, fit_id, _ = shared
        # An export made elsewhere (the CLI's: a content address, not a stored id).
        stored = model_of(client, fit_id)
        model = type(stored)("Cu elsewhere", stored.coefficients, stored.eta_i_range, stored.source, model=stored.model)
        text = export_material(library_material("Cu"), "mtlx", 1.33, model=model)
        response = post(client, text)
        assert response.status_code == 201, response.text
        new = response.json()
        assert new["id"] != fit_id and new["kind"] == "curves" and new["name"] == "Cu elsewhere"
        assert model_of(client, new["id"]) == model  # the same coefficients, bit for bit
        again = post(client, text)
        assert again.status_code == 200 and again.json()["id"] == new["id"]
        # Its own exports name it.
        glb = client.get(f"{API}/fits/{new['id']}/pack?format=glb&eta_i=1.5").content
        assert post(client, glb).json()["id"] == new["id"]

    def test_to_the_bit(self, shared):
        client, fit_id, files = shared
        stored = encode_pack([model_of(client, fit_id)])
        assert files["binary"] == stored

    @pytest.mark.parametrize(
        "damage, words",
        [
            (lambda f: f["binary"][:-1] + bytes([f["binary"][-1] ^ 1]), "checksum mismatch"),
            (lambda f: f["binary"][:20], "truncated"),
            # The document's fit id changed, not the material's.
            (lambda f: f["mtlx"].replace(b'coatedfresnel_fit_id="', b'coatedfresnel_fit_id="f', 1), "differ in fit_id"),
            (lambda f: gltf_extras(f["gltf"], eta_i=9), "`eta_i` must lie in [1, 3], got 9"),
            (
                lambda f: gltf_extras(f["gltf"], eta_i=2.0),
                "the coat index EXT_materials_coated_conductor is drawn under",
            ),
            (lambda f: f["blender"].replace(b"PACK = '", b"PACK = 'x", 1), "damaged fit model (PACK)"),
            (lambda f: f["glb"][:-4], "damaged GLB"),
            (lambda f: b'<materialx version="1.39"/>', "one surfacematerial"),
            (lambda f: b"\xff\xfegarbage", "neither a pack, a GLB nor UTF-8"),
            (lambda f: b"hello", "is not a pack, its JSON view, a glTF/GLB"),
            (lambda f: b"", "`file` is empty"),
        ],
        ids=[
            "crc",
            "truncated",
            "mtlx-identity",
            "gltf-eta",
            "gltf-coat-ior",
            "blender-pack",
            "glb-length",
            "no-material",
            "binary-garbage",
            "text",
            "empty",
        ],
    )
    def test_damaged_files_422(self, shared, damage, words):
        client, _, files = shared
        response = post(client, damage(files))
        assert response.status_code == 422, response.text
        assert words in json.dumps(response.json())

    def test_id_and_coefficients_disagree_422(self, shared):
        client, fit_id, files = shared
        asset = json.loads(files["gltf"])
        info = asset["materials"][0]["extras"]["coated_fresnel"]
        other = pack_from_json(client.get(f"{API}/fits/{fit_id}/pack?format=json").text)[0]
        halves = other.coefficients.copy()
        halves.flat[0] = -halves.flat[0] if halves.flat[0] else 0.5
        other = type(other)(other.name, halves, other.eta_i_range, other.source, model=other.model)
        info["pack"] = base64.b64encode(encode_pack([other])).decode()
        del asset["materials"][0]["extensions"]["EXT_materials_coated_conductor"]
        response = post(client, json.dumps(asset).encode())
        assert response.status_code == 422, response.text
        assert "coefficients are not that fit's" in response.json()["detail"]


class TestImportGuards:
    def test_token_required_401(self, tmp_path):
        with app_client(tmp_path, require_token=True, api_token="s3cret") as client:
            response = post(client, b"CFPK")
            assert response.status_code == 401 and response.headers["www-authenticate"] == "Bearer"
            # Past the token check: refused for what the file is.
            allowed = client.post(
                f"{API}/fits/import", files={"file": ("a", b"CFPK")}, headers={"Authorization": "Bearer s3cret"}
            )
            assert allowed.status_code == 422 and "truncated" in allowed.json()["detail"]

    def test_too_large_413(self, tmp_path):
        with app_client(tmp_path, max_upload_bytes=4096) as client:
            response = post(client, b"x" * 10_000)
            assert response.status_code == 413, response.text
