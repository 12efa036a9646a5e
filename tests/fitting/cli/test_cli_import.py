"""``python -m fitting import FILE``: every pack and export back to the fit's coefficients, to the bit."""

from __future__ import annotations

import json

import pytest
from conftest import run_command

from fitting.cli.main import main
from fitting.exports import export_material, export_values
from fitting.fits.kinds import fit_model
from fitting.models.pack import encode_pack, material_from_json, pack_to_json
from fitting.optics.library import library_material

FIT_ID = "c0ffee00" * 4


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Cr's fit and each of its files; the exports name a stored fit id."""
    nk = library_material("Cr")
    model = fit_model(nk, (1.0, 2.5), "rgb-conductor", evaluate=False).packed
    values = export_values(nk, 1.5, model=model, fit_id=FIT_ID)
    folder = tmp_path_factory.mktemp("import")
    out = {"binary": encode_pack([model]), "json": pack_to_json([model]).encode()}
    for format in ("mtlx", "openpbr", "blender", "gltf", "glb"):
        out[format] = export_material(values, format, 1.5)
    paths = {}
    for format, data in out.items():
        paths[format] = folder / f"cr.{format}"
        paths[format].write_bytes(data)
    return model, paths


@pytest.mark.slow  # one fit and the exports of every tool, about 4 s
class TestImportCommand:
    @pytest.mark.parametrize("format", ["binary", "json", "mtlx", "openpbr", "blender", "gltf", "glb"])
    def test_every_format_to_the_bit(self, files, format, capsys, tmp_path):
        model, paths = files
        pack = tmp_path / "back.cfpk"
        assert main(["import", str(paths[format]), "-o", str(pack)]) == 0
        answer = json.loads(capsys.readouterr().out)
        assert answer["format"] == format
        (material,) = answer["materials"]
        assert material_from_json(material) == model
        assert pack.read_bytes() == encode_pack([model])
        if format in ("binary", "json"):
            assert answer["fit_id_from"] == "content"
        else:
            assert answer["fit_id"] == FIT_ID and answer["fit_id_from"] == "file"
            assert answer["identity"]["eta_i"] == 1.5

    def test_damaged_file_exits_2(self, files, tmp_path):
        _, paths = files
        damaged = tmp_path / "damaged.cfpk"
        data = bytearray(paths["binary"].read_bytes())
        data[-1] ^= 1
        damaged.write_bytes(bytes(data))
        result = run_command("fitting", "import", str(damaged))
        assert result.returncode == 2
        assert "`file` is not a pack" not in result.stderr and "checksum mismatch" in result.stderr
