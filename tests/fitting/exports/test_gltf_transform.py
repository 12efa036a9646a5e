"""
EXT_materials_coated_conductor through glTF Transform
(web/gltf-transform/, its CLI pinned in web/gltf-transform/package-lock.json):
with the package's extension class in the CLI's config, `gltf-transform copy`
and `gltf-transform optimize` write every exported extension object back
equal (both kinds); without it the CLI drops the extension, which is what the
class is for.
"""

from __future__ import annotations

import json
import struct
import subprocess
from pathlib import Path

import pytest

from fitting.exports import export_material
from fitting.exports.gltf_coated import EXTENSION_NAME
from fitting.fits.kinds import fit_model
from fitting.models.kinds import MODEL_KINDS
from fitting.optics.library import library_material

pytestmark = pytest.mark.slow

PACKAGE = Path(__file__).resolve().parents[3] / "web" / "gltf-transform"
CLI = PACKAGE / "node_modules" / ".bin" / "gltf-transform"
CONFIG = PACKAGE / "gltf-transform.config.mjs"


def glb_json(path: Path) -> dict:
    """The JSON chunk of a GLB file (glTF 2.0, 5.2: header, then the JSON chunk)."""
    data = path.read_bytes()
    magic, version, _ = struct.unpack_from("<III", data, 0)
    length, kind = struct.unpack_from("<II", data, 12)
    assert (magic, version, kind) == (0x46546C67, 2, 0x4E4F534A)
    return json.loads(data[20 : 20 + length])


def transform(command: list[str], source: Path, out: Path, config: bool = True) -> dict:
    args = [str(CLI), *command[:1], str(source), str(out), *command[1:]]
    if config:
        args += ["--config", str(CONFIG)]
    result = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr + result.stdout
    return glb_json(out)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Cu exported at eta_i 1.8 with each kind's model: {kind: (path, extension object and clear coat)}."""
    nk = library_material("Cu")
    out = {}
    for kind in MODEL_KINDS:
        document = export_material(nk, "gltf", 1.8, model=fit_model(nk, (1.0, 2.5), kind).packed)
        path = tmp_path_factory.mktemp(kind) / "coated.gltf"
        path.write_bytes(document if isinstance(document, bytes) else document.encode())
        extensions = json.loads(document)["materials"][0]["extensions"]
        out[kind] = path, {name: extensions[name] for name in (EXTENSION_NAME, "KHR_materials_clearcoat")}
    return out


@pytest.mark.parametrize("command", [["copy"], ["optimize", "--texture-compress", "false"]], ids=["copy", "optimize"])
def test_cli_keeps_the_extension(exported, tmp_path, command):
    for kind, (path, extension) in exported.items():
        written = transform(command, path, tmp_path / f"{kind}.glb")
        extensions = written["materials"][0]["extensions"]
        assert extensions[EXTENSION_NAME] == extension[EXTENSION_NAME], kind
        # The coat the metal lies under, its index (the nested draft) included.
        assert extensions["KHR_materials_clearcoat"] == extension["KHR_materials_clearcoat"], kind
        assert extensions["KHR_materials_clearcoat"]["extensions"]["KHR_materials_clearcoat_ior"]["clearcoatIor"] == 1.8
        assert {EXTENSION_NAME, "KHR_materials_clearcoat_ior"} <= set(written["extensionsUsed"])
        assert EXTENSION_NAME not in written.get("extensionsRequired", [])


def test_without_the_class_the_cli_drops_it(exported, tmp_path):
    path, _ = next(iter(exported.values()))
    written = transform(["copy"], path, tmp_path / "plain.glb", config=False)
    assert EXTENSION_NAME not in written["materials"][0].get("extensions", {})
