"""``python -m fitting fit MATERIAL --export FORMAT --eta-i X -o FILE``."""

from __future__ import annotations

import json
import subprocess

import pytest
from conftest import run_command

from fitting.domain import DEFAULT_ETA_I_RANGE
from fitting.exports import export_material
from fitting.fits.kinds import fit_model
from fitting.optics.library import library_material


def cli(*args: str) -> subprocess.CompletedProcess:
    return run_command("fitting", *args)


class TestExportOption:
    @pytest.mark.slow  # 2.6 s (all cases 2.6 s) in a --durations=0 run
    def test_writes_the_export(self, tmp_path):
        out = tmp_path / "au.mtlx"
        result = cli("fit", "Au", "--export", "mtlx", "--eta-i", "1.5", "-o", str(out))
        assert result.returncode == 0, result.stderr
        # The CLI's export carries its fit's float16 model (read back by `import`).
        model = fit_model(library_material("Au"), DEFAULT_ETA_I_RANGE, evaluate=False).packed
        assert out.read_bytes() == export_material(library_material("Au"), "mtlx", 1.5, model=model)

    @pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
    def test_stdout_and_roughness(self):
        result = cli("fit", "Cr", "--export", "gltf", "--eta-i", "2", "--roughness", "0.5")
        assert result.returncode == 0, result.stderr
        material = json.loads(result.stdout)["materials"][0]
        assert material["pbrMetallicRoughness"]["roughnessFactor"] == 0.5
        assert material["extras"]["coated_fresnel"]["eta_i"] == 2.0
        extension = material["extensions"]["EXT_materials_coated_conductor"]
        clearcoat = material["extensions"]["KHR_materials_clearcoat"]
        assert extension["kind"] == "coated-conductor"
        assert clearcoat["extensions"]["KHR_materials_clearcoat_ior"]["clearcoatIor"] == 2.0

    @pytest.mark.slow
    def test_gltf_carries_the_kind(self):
        result = cli("fit", "Cu", "--export", "gltf", "--model", "rgb-conductor", "--eta-i", "1.33")
        assert result.returncode == 0, result.stderr
        extension = json.loads(result.stdout)["materials"][0]["extensions"]["EXT_materials_coated_conductor"]
        assert extension["kind"] == "rgb-conductor" and set(extension["coefficients"]) == {"n", "k"}

    @pytest.mark.slow  # starts a process or GL context
    def test_bad_eta_i(self):
        result = cli("fit", "Au", "--export", "openpbr", "--eta-i", "0.8")
        assert result.returncode == 2
        assert "`eta_i` must lie in [1, 3], got 0.8" in result.stderr

    @pytest.mark.slow  # starts a process or GL context
    def test_bad_format(self):
        result = cli("fit", "Au", "--export", "usd")
        assert result.returncode == 2 and "invalid choice: 'usd'" in result.stderr
