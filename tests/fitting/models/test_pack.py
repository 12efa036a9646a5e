"""fitting.models.pack: the binary pack and its JSON view."""

import json
import struct

import numpy as np
import pytest

from fitting.models.pack import (
    PackedMaterial,
    decode_pack,
    encode_pack,
    halves_to_uint32,
    material_to_json,
    pack_from_json,
    pack_to_json,
    to_float16,
)

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


def _material(name="Au", degree=2, source="test source"):
    rng = np.random.default_rng(len(name) + degree)
    C = to_float16(rng.normal(size=(3, 3, degree + 1)))
    return PackedMaterial(name, C, (1.0, 2.5), source=source)


class TestPack:
    def test_binary_round_trip_exact(self):
        materials = [_material("Au"), _material("Cu∞", degree=0), _material("Al", degree=1, source="")]
        data = encode_pack(materials)
        assert data[:4] == b"CFPK"
        decoded = decode_pack(data)
        assert decoded == materials
        assert encode_pack(decoded) == data

    def test_json_round_trip_exact(self):
        materials = [_material("Au"), _material("Ni", degree=1)]
        assert pack_from_json(pack_to_json(materials)) == materials
        view = material_to_json(materials[0])
        assert set(view) >= {"name", "eta_i_range", "colour_space", "coefficients", "source", "metrics"}
        assert len(view["coefficients"]["alpha"]) == 3 and len(view["coefficients"]["F0"][0]) == 3

    def test_size_of_27_halves(self):
        data = encode_pack([_material("Au", source="")])
        assert len(data) == 12 + 2 + 2 + 2 + 12 + 54 + 4

    @pytest.mark.parametrize(
        "damage, message",
        [
            (lambda d: d[:-3], "wrong length"),
            (lambda d: d[:10], "truncated"),
            (lambda d: b"XXXX" + d[4:], "magic"),
            (lambda d: d[:4] + struct.pack("<H", 9) + d[6:], "version 9"),
            (lambda d: d + b"\x00", "wrong length"),
            (lambda d: d[:40] + bytes([d[40] ^ 0xFF]) + d[41:], "checksum"),
        ],
    )
    def test_damaged_files_refused(self, damage, message):
        data = encode_pack([_material()])
        with pytest.raises(ValueError, match=message):
            decode_pack(damage(data))

    def test_float16_range_refused(self):
        with pytest.raises(ValueError, match="float16 range"):
            to_float16([1.0, 70000.0])
        with pytest.raises(ValueError, match="exactly representable in float16"):
            PackedMaterial("x", np.full((3, 3, 3), 0.1), (1.0, 2.5))

    def test_halves_to_uint32(self):
        C = _material().coefficients
        words = halves_to_uint32(C)
        assert words.dtype == np.uint32 and words.size == 14
        halves = C.ravel()
        bits = halves.view(np.uint16)
        assert words[0] & 0xFFFF == bits[0] and words[0] >> 16 == bits[1]
        assert words[13] & 0xFFFF == bits[26] and words[13] >> 16 == 0

    def test_bad_json_pack(self):
        with pytest.raises(ValueError, match="not valid JSON"):
            pack_from_json("{")
        with pytest.raises(ValueError, match="`format`"):
            pack_from_json("{}")
        view = json.loads(pack_to_json([_material()]))
        view["materials"][0]["coefficients"]["F0"] = [[1, 2]]
        with pytest.raises(ValueError, match="`coefficients` must hold"):
            pack_from_json(json.dumps(view))
