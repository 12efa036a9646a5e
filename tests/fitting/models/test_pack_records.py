"""fitting.models.pack.material_record_bytes: record sizes."""

import numpy as np
import pytest
from conftest import SHOWROOM_SCENE

from fitting.models.pack import PackedMaterial, encode_pack, material_record_bytes

SCENE = SHOWROOM_SCENE  # and the `showroom` fixture: its fit, once a session (tests/conftest.py)


class TestRecordBytes:
    @pytest.mark.parametrize("degree", [0, 1, 2])
    def test_matches_the_binary_pack(self, degree):
        material = PackedMaterial("Gold é", np.zeros((3, 3, degree + 1), np.float16), (1.0, 2.0), source="J&C 1972")
        pack = encode_pack([material])
        header, crc = 12, 4
        assert material_record_bytes("Gold é", "J&C 1972", degree) == len(pack) - header - crc
