"""
The pack with model kinds: version 2 binary and JSON round trips of both
kinds, version 1 packs (written before the kinds) still read, the JSON view
of an rgb-conductor, and precise refusals.
"""

from __future__ import annotations

import json
import struct
import zlib

import numpy as np
import pytest

from fitting.models.kinds import MODEL_KINDS, check_model, coefficient_count, model_ACEScg
from fitting.models.pack import (
    PACK_VERSION,
    PackedMaterial,
    decode_pack,
    encode_pack,
    halves_to_uint32,
    material_from_json,
    material_record_bytes,
    material_to_json,
    pack_from_json,
    pack_to_json,
    to_float16,
)
from fitting.models.rgb_conductor import rgb_conductor_model, rgb_fresnel_conductor

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


def coated(name="Au", degree=2):
    rng = np.random.default_rng(degree)
    return PackedMaterial(name, to_float16(rng.normal(size=(3, 3, degree + 1))), (1.0, 2.5), source="s")


def rgb(name="Cu", n=(0.26, 0.47, 1.32), k=(3.03, 2.31, 1.92)):
    return PackedMaterial(name, to_float16([n, k]), (1.2, 2.0), source="rgb src", model="rgb-conductor")


def version_1_bytes(materials):
    """A pack as the version-1 writer laid it out (degree u8, 3 reserved bytes)."""
    body = bytearray()
    for m in materials:
        for text in (m.name, m.source):
            raw = text.encode()
            body += struct.pack("<H", len(raw)) + raw
        body += struct.pack("<ffB3x", *m.eta_i_range, m.degree) + m.coefficients.astype("<f2").tobytes()
    head = struct.pack("<4sHHI", b"CFPK", 1, len(materials), 12 + len(body) + 4)
    data = head + bytes(body)
    return data + struct.pack("<I", zlib.crc32(data))


class TestBinary:
    def test_version_2_round_trip_both_kinds(self):
        materials = [coated(), rgb(), coated("Ni", 0)]
        data = encode_pack(materials)
        assert struct.unpack_from("<H", data, 4)[0] == PACK_VERSION == 2
        decoded = decode_pack(data)
        assert decoded == materials
        assert [m.model for m in decoded] == ["coated-conductor", "rgb-conductor", "coated-conductor"]
        assert decoded[1].coefficients.tobytes() == materials[1].coefficients.tobytes()
        assert encode_pack(decoded) == data

    def test_rgb_record_size(self):
        m = rgb()
        data = encode_pack([m])
        assert len(data) == 12 + material_record_bytes(m.name, m.source, 0, m.model) + 4
        assert material_record_bytes("x", "", 0, "rgb-conductor") == 2 + 1 + 2 + 12 + 12

    def test_version_1_pack_still_decodes(self):
        materials = [coated(), coated("Al", 1)]
        old = version_1_bytes(materials)
        decoded = decode_pack(old)
        assert decoded == materials and all(m.model == "coated-conductor" for m in decoded)
        # The version-1 writer is still available for old readers, byte for byte.
        assert encode_pack(materials, version=1) == old

    def test_version_1_cannot_hold_rgb_conductor(self):
        with pytest.raises(ValueError, match="`version` 1 holds only coated-conductor"):
            encode_pack([rgb()], version=1)

    def test_unknown_kind_code_refused(self):
        data = bytearray(encode_pack([rgb()]))
        kind_at = 12 + 2 + 2 + 2 + 7 + 9  # header, name "Cu", source "rgb src", eta_lo, eta_hi, degree
        assert data[kind_at] == 1
        data[kind_at] = 7
        data[-4:] = struct.pack("<I", zlib.crc32(bytes(data[:-4])))
        with pytest.raises(ValueError, match="model kind code 7"):
            decode_pack(bytes(data))

    def test_unknown_version_refused(self):
        data = encode_pack([coated()])
        with pytest.raises(ValueError, match="versions 1, 2 are supported"):
            decode_pack(data[:4] + struct.pack("<H", 3) + data[6:])

    def test_halves_to_uint32_of_six(self):
        m = rgb()
        words = halves_to_uint32(m.coefficients)
        bits = m.coefficients.ravel().view(np.uint16)
        assert words.size == 3 and words[1] & 0xFFFF == bits[2] and words[1] >> 16 == bits[3]


class TestJSONView:
    def test_rgb_conductor_shape(self):
        m = rgb()
        view = material_to_json(m)
        assert view["model"] == "rgb-conductor"
        assert view["coefficients"] == {
            "n": [float(v) for v in m.coefficients[0]],
            "k": [float(v) for v in m.coefficients[1]],
        }
        assert "degree" not in view
        assert json.loads(json.dumps(view)) == view  # plain JSON numbers, exactly the halves

    def test_coated_conductor_names_its_kind(self):
        view = material_to_json(coated())
        assert view["model"] == "coated-conductor" and view["degree"] == 2
        assert set(view["coefficients"]) == {"F0", "a", "alpha"}

    def test_round_trip_both_kinds(self):
        materials = [rgb(), coated()]
        text = pack_to_json(materials)
        assert json.loads(text)["version"] == 2
        assert pack_from_json(text) == materials

    def test_version_1_json_still_reads(self):
        view = json.loads(pack_to_json([coated()]))
        view["version"] = 1
        for m in view["materials"]:
            del m["model"]
        assert pack_from_json(json.dumps(view)) == [coated()]
        view["materials"].append(material_to_json(rgb()))
        with pytest.raises(ValueError, match="version` 1 holds only coated-conductor"):
            pack_from_json(json.dumps(view))

    @pytest.mark.parametrize(
        "change, message",
        [
            (lambda v: v.update(model="phong"), "`model` must be one of coated-conductor, rgb-conductor"),
            (lambda v: v["coefficients"].update(n=[1.0, 2.0]), "`coefficients` must hold n and k"),
            (lambda v: v["coefficients"].update(k=[[1.0], [2.0], [3.0]]), "`coefficients` must hold n and k"),
            (lambda v: v["coefficients"].update(k=[1.0, -1.0, 0.0]), "k must be >= 0"),
            (lambda v: v["coefficients"].update(n=[0.1, 0.2, 0.3000001]), "exactly representable in float16"),
        ],
    )
    def test_bad_rgb_view_refused(self, change, message):
        view = material_to_json(rgb())
        change(view)
        with pytest.raises(ValueError, match=message):
            material_from_json(view)


class TestKinds:
    def test_names(self):
        assert tuple(MODEL_KINDS) == ("coated-conductor", "rgb-conductor")
        assert [k.code for k in MODEL_KINDS.values()] == [0, 1]
        with pytest.raises(ValueError, match="`model` must be one of"):
            check_model("rgb")
        assert coefficient_count("rgb-conductor") == 6 and coefficient_count("coated-conductor", 1) == 18

    def test_model_is_relative_index_fresnel(self):
        # (n + i k) / eta_i: scaling the index and the coating alike changes nothing.
        C = np.array([[0.26, 0.47, 1.32], [3.03, 2.31, 1.92]])
        mu = np.linspace(0.0, 1.0, 7)
        np.testing.assert_allclose(
            rgb_conductor_model(mu, 2.0, C),
            rgb_conductor_model(mu, 1.0, C / 2.0),
            atol=1e-15,  # halving
            # is exact, so both sides form the same relative index; only the
            # kernel's ~20 roundings of R <= 1 in another order: 9 u64 = 1e-15
        )
        np.testing.assert_allclose(
            model_ACEScg("rgb-conductor", mu, 1.5, C, (1.0, 2.5)), rgb_fresnel_conductor(mu, 1.5, C[0], C[1]), atol=0
        )
        F = rgb_conductor_model(mu, np.array([[1.0], [2.5]]), C)
        assert F.shape == (2, 7, 3) and np.all(F[:, 0] == 1.0)  # grazing incidence

    def test_model_refuses_bad_input(self):
        with pytest.raises(ValueError, match=r"shape \(2, 3\)"):
            rgb_conductor_model(0.5, 1.5, np.ones((3, 3)))
        with pytest.raises(ValueError, match="n must be > 0"):
            rgb_conductor_model(0.5, 1.5, [[0.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
        with pytest.raises(ValueError, match="`cos_theta` must be finite"):
            rgb_conductor_model(np.nan, 1.5, [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
