"""fitting.models.pack.material_record_bytes: record sizes."""

import numpy as np
import pytest

from fitting.fits.scene_fit import fit_scene
from fitting.fits.scene_schema import parse_scene
from fitting.models.pack import PackedMaterial, encode_pack, material_record_bytes

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


class TestRecordBytes:
    @pytest.mark.parametrize("degree", [0, 1, 2])
    def test_matches_the_binary_pack(self, degree):
        material = PackedMaterial("Gold é", np.zeros((3, 3, degree + 1), np.float16),
                                  (1.0, 2.0), source="J&C 1972")
        pack = encode_pack([material])
        header, crc = 12, 4
        assert material_record_bytes("Gold é", "J&C 1972", degree) == len(pack) - header - crc
