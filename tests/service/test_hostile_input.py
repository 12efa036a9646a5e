"""
Hostile input against a real ``python -m service`` process on 127.0.0.1.

Generated classes of hostile requests (randomised with a fixed seed, many
variants per class, so that the suite tests classes rather than a list of
requests): YAML alias/anchor bombs of several shapes, deep nesting in JSON
and YAML (files and request bodies), huge formula wavelength ranges, huge
sample counts, fields of every wrong type, booleans as numbers, NaN and
Infinity literals, oversized bodies (declared and streamed), malformed
multipart, text that is not UTF-8, byte-order marks, and CSV with huge
fields, rows and columns.

The corpus is sent once (module fixture) by a few concurrent clients while a
separate process polls ``/healthz``; the tests then assert, per class, that
every answer is a 4xx with a JSON error body whose message names the
problem and repeats at most a short excerpt of the input, and, for the whole
run, that the server's memory grew by less than 300 MB and the ``/healthz``
p99 stayed under 0.5 s.
"""

from __future__ import annotations

import base64
import functools
import json
import random
import re
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import httpx
import loopback
import pytest

from conftest import server_process

pytestmark = pytest.mark.server

API = "/api/v1"
SEED = 20261201
MAX_ECHO = 80
"""Longest run of the hostile input an answer may repeat."""
RSS_GROWTH_LIMIT_MB = 300.0
HEALTHZ_P99_LIMIT_S = 0.5
CLIENTS = 4
"""Concurrent hostile clients."""
UPLOAD_LIMIT = 2_000_000
BODY_LIMIT = 1_000_000
"""The service defaults (COATED_MAX_UPLOAD_BYTES, COATED_MAX_BODY_BYTES)."""


@dataclass
class Case:
    """One hostile request and what its answer must say."""

    klass: str
    label: str
    method: str
    path: str
    expect: str
    """Regular expression the error message must match (case-insensitive)."""
    payload: bytes
    """The hostile bytes, for the echo check."""
    request: dict[str, Any] = field(default_factory=dict)
    """Keyword arguments of ``httpx.Client.request``."""
    statuses: tuple[int, ...] = (400, 413, 415, 422)


# -- building blocks -------------------------------------------------------

GOOD_ROWS = "\n".join(f"        {0.35 + 0.05 * i:.2f} {1.5 - 0.1 * i:.3f} {1.8 + 0.4 * i:.3f}" for i in range(10))
GOOD_NK_ENTRY = f"  - type: tabulated nk\n    data: |\n{GOOD_ROWS}\n"
GOOD_JSON = {"wavelength_nm": [400.0, 500.0, 600.0], "n": [1.5, 0.9, 0.3], "k": [1.9, 2.5, 3.2]}


def upload(klass: str, label: str, content: bytes | str, filename: str, expect: str, **form: str) -> Case:
    data = content.encode() if isinstance(content, str) else content
    return Case(
        klass,
        label,
        "POST",
        f"{API}/fits/upload",
        expect,
        data,
        {"files": {"file": (filename, data, "application/octet-stream")}, "data": form},
    )


def body(
    klass: str,
    label: str,
    path: str,
    content: bytes | str,
    expect: str,
    content_type: str = "application/json",
    **extra: Any,
) -> Case:
    data = content.encode() if isinstance(content, str) else content
    return Case(
        klass, label, "POST", path, expect, data, {"content": data, "headers": {"content-type": content_type}}, **extra
    )


def json_body(klass: str, label: str, path: str, value: Any, expect: str) -> Case:
    return body(klass, label, path, json.dumps(value), expect)


def yaml_upload(klass: str, label: str, text: str, expect: str) -> Case:
    return upload(klass, label, text, "hostile.yml", expect)


# -- generators: each returns many randomised variants of one class ---------


def gen_yaml_alias_bomb(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(24):
        levels, fan = rng.randint(4, 14), rng.randint(2, 12)
        shape = rng.choice(["flow", "block", "mapping", "merge", "scalar", "recursive", "key"])
        lines = []
        if shape == "flow":
            lines.append(f"l0: &l0 [{rng.choice(['lol', '0.5 1 2', 'x' * rng.randint(1, 50)])}]")
            for lv in range(1, levels):
                lines.append(f"l{lv}: &l{lv} [" + ", ".join([f"*l{lv - 1}"] * fan) + "]")
        elif shape == "block":
            lines.append("l0: &l0\n  - lol")
            for lv in range(1, levels):
                lines.append(f"l{lv}: &l{lv}\n" + "".join(f"  - *l{lv - 1}\n" for _ in range(fan)))
        elif shape == "mapping":
            lines.append("l0: &l0 {a: lol}")
            for lv in range(1, levels):
                lines.append(f"l{lv}: &l{lv} {{" + ", ".join(f"k{j}: *l{lv - 1}" for j in range(fan)) + "}")
        elif shape == "merge":
            lines.append("l0: &l0 {a0: lol}")
            for lv in range(1, levels):
                lines.append(f"l{lv}: &l{lv} {{<<: [" + ", ".join([f"*l{lv - 1}"] * fan) + f"], b{lv}: 1}}")
        elif shape == "scalar":
            lines.append(f"s: &s '{'0.5 1.0 2.0 ' * rng.randint(10, 2000)}'")
            lines.append("t: [" + ", ".join(["*s"] * rng.randint(50, 3000)) + "]")
        elif shape == "recursive":
            lines.append("r: &r [*r, *r]")
        else:
            lines.append("k: &k [a, b]")
            lines.append("m: {? *k : 1, ? [*k, *k] : 2}")
        where = rng.choice(["REFERENCES", "DATA", "data", "COMMENTS"])
        last = (
            f"l{levels - 1}"
            if shape in ("flow", "block", "mapping", "merge")
            else {"scalar": "s", "recursive": "r", "key": "k"}[shape]
        )
        doc = "\n".join(lines) + "\n"
        if where == "REFERENCES":
            doc += f"REFERENCES: *{last}\nDATA:\n{GOOD_NK_ENTRY}"
        elif where == "DATA":
            doc += f"DATA: *{last}\n"
        elif where == "data":
            doc += f"DATA:\n  - type: tabulated nk\n    data: *{last}\n"
        else:
            doc += f"COMMENTS: *{last}\nDATA:\n{GOOD_NK_ENTRY}"
        cases.append(yaml_upload("yaml_alias_bomb", f"{shape}-{where}-{levels}x{fan}-{i}", doc, r"alias|merge"))
    return cases


def gen_deep_nesting(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(10):
        depth = rng.choice([40, 200, 1_000, 5_000, 100_000, rng.randint(33, 600_000)])
        opener, closer = rng.choice([("[", "]"), ("{a: ", "}"), ("[{x: ", "}]")])
        text = "DATA:\n  - type: " + opener * depth + "1" + closer * depth + "\n"
        if len(text) > UPLOAD_LIMIT - 1000:
            depth = (UPLOAD_LIMIT - 1000) // (len(opener) + len(closer))
            text = "DATA: " + opener * depth + closer * depth
        cases.append(yaml_upload("deep_nesting", f"yaml-flow-{depth}-{i}", text, r"nest|deep"))
    for i in range(4):
        depth = rng.randint(40, 300)
        text = "".join("  " * d + "-\n" for d in range(depth)) + "  " * depth + "- x\n"
        cases.append(yaml_upload("deep_nesting", f"yaml-block-{depth}-{i}", text, r"nest|deep"))
    for i in range(10):
        depth = rng.choice([40, 999, 5_000, 100_000, rng.randint(33, 900_000)])
        opener, closer = rng.choice([("[", "]"), ('{"n":', "}"), ('[{"k":', "}]")])
        depth = min(depth, (UPLOAD_LIMIT - 1000) // (len(opener) + len(closer)))
        text = '{"wavelength_nm": ' + opener * depth + "1" + closer * depth + ', "n": [1], "k": [1]}'
        cases.append(upload("deep_nesting", f"json-file-{depth}-{i}", text, "deep.json", r"nest|deep"))
    for i in range(10):
        depth = rng.choice([1_000, 50_000, 200_000, rng.randint(2_000, 400_000)])
        opener, closer = rng.choice([("[", "]"), ('{"a":', "}")])
        depth = min(depth, (BODY_LIMIT - 1000) // (len(opener) + len(closer)))
        path = rng.choice([f"{API}/fits", f"{API}/scenes", f"{API}/packs", f"{API}/fits/from-curves"])
        text = '{"nk": ' + opener * depth + closer * depth + "}"
        cases.append(body("deep_nesting", f"json-body-{depth}-{i}", path, text, r"nest|deep"))
    return cases


FORMULA_COEFFICIENTS = {
    1: "0 1.03 0.07 0.23 0.15",
    2: "0 1.03 0.006",
    3: "2.2 -0.01 2",
    4: "2.2 0.01 0 0.05 2",
    5: "1.45 0.004 -2",
    6: "0 0.05 238",
    7: "1.5 0.004 0 0 0 0",
    8: "0.5 0.1 0.01 0.01",
    9: "2.1 0.1 0.02 0.01 0.3 0.2",
}


def gen_huge_wavelength_range(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(28):
        number = rng.randint(1, 9)
        lo = rng.choice([1.0, 10.0, 1e3, 5.0]) * rng.uniform(1.0, 3.0)
        hi = lo * 10 ** rng.uniform(4, 300)
        kind = rng.choice(["above", "nan", "inf", "reversed", "equal", "negative"])
        if kind == "above":
            wr = f"{lo:g} {hi:g}"
            expect = r"samples"
        elif kind == "nan":
            wr, expect = f"{rng.choice(['nan', '.nan', 'NaN'])} {hi:g}", r"wavelength_range"
        elif kind == "inf":
            wr, expect = f"{lo:g} {rng.choice(['inf', '1e999'])}", r"wavelength_range|samples"
        elif kind == "reversed":
            wr, expect = f"{hi:g} {lo:g}", r"wavelength_range"
        elif kind == "equal":
            wr, expect = f"{lo:g} {lo:g}", r"wavelength_range"
        else:
            wr, expect = f"-{hi:g} -{lo:g}", r"wavelength_range|samples|wavelength|> 0|real n"
        text = (
            f"DATA:\n  - type: formula {number}\n    wavelength_range: {wr}\n"
            f"    coefficients: {FORMULA_COEFFICIENTS[number]}\n"
        )
        if rng.random() < 0.4:
            text += f"  - type: tabulated k\n    data: |\n        {lo:g} 0.1\n        {hi:g} 0.2\n"
        cases.append(yaml_upload("huge_wavelength_range", f"f{number}-{kind}-{i}", text, expect))
    return cases


def gen_huge_samples(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(5):
        rows = rng.randint(20_001, 80_000)
        text = "wavelength_nm,n,k\n" + "".join(f"{300 + j * 0.01:.2f},1,1\n" for j in range(rows))
        cases.append(upload("huge_samples", f"csv-{rows}-{i}", text, "many.csv", r"at most \d+"))
    for i in range(4):
        rows = rng.randint(20_001, 100_000)
        data = "".join(f"        {0.3 + j * 1e-5:.5f} 1 1\n" for j in range(rows))
        if len(data) > UPLOAD_LIMIT - 200:
            rows = 100_001
            data = "        0.5 1 1\n" * rows
        text = f"DATA:\n  - type: tabulated nk\n    data: |\n{data}"
        if len(text) <= UPLOAD_LIMIT:
            cases.append(yaml_upload("huge_samples", f"yaml-{rows}-{i}", text, r"at most \d+"))
    for i in range(4):
        count = rng.randint(20_001, 150_000)
        values = "[" + ",".join(str(400 + j) for j in range(count)) + "]"
        text = f'{{"wavelength_nm": {values}, "n": {values}, "k": {values}}}'
        if len(text) > UPLOAD_LIMIT:
            text = f'{{"wavelength_nm": {values}, "n": [1], "k": [1]}}'
        cases.append(upload("huge_samples", f"json-file-{count}-{i}", text, "many.json", r"at most \d+"))
    for i in range(6):
        count = rng.randint(20_001, 60_000)
        value = {"name": "big", "nk": {"wavelength_nm": list(range(1, count + 1)), "n": [1.0] * 3, "k": [1.0] * 3}}
        path = rng.choice([f"{API}/fits", f"{API}/scenes"])
        if path.endswith("scenes"):
            value = {"name": "s", "materials": [{"name": "m", "nk": value["nk"], "eta_i": 1.5}]}
        cases.append(json_body("huge_samples", f"json-body-{count}-{i}", path, value, r"at most \d+|\d+ items"))
    return cases


YAML_WRONG_VALUES = {
    "a number": ["12", "-3.5e+9", "0x1F", "1_000"],
    "a list": ["[a, b]", "[]", "[[1, 2], [3]]"],
    "a map": ["{a: b}", "{}", "{? x : y}"],
    "a date": ["2020-01-02", "2001-12-14t21:59:43.10-05:00"],
    "binary data": ["!!binary aGVsbG8=", "!!binary " + base64.b64encode(bytes(range(40))).decode()],
    "a boolean": ["true", "no", "off"],
    "a set": ["!!set {a, b}"],
}


def gen_wrong_types(rng: random.Random) -> list[Case]:
    cases = []
    kinds = list(YAML_WRONG_VALUES)
    for i in range(40):
        kind = rng.choice(kinds)
        value = rng.choice(YAML_WRONG_VALUES[kind])
        target = rng.choice(
            ["REFERENCES", "DATA", "DATA[0]", "type", "data", "coefficients", "wavelength_range", "top"]
        )
        if target == "REFERENCES":
            text = f"REFERENCES: {value}\nDATA:\n{GOOD_NK_ENTRY}"
        elif target == "DATA":
            text = f"DATA: {value}\n"
        elif target == "DATA[0]":
            text = f"DATA:\n  - {value}\n"
        elif target == "type":
            text = f"DATA:\n  - type: {value}\n    data: '0.5 1 1'\n"
        elif target == "data":
            text = f"DATA:\n  - type: tabulated nk\n    data: {value}\n"
        elif target == "coefficients":
            if kind == "a number":
                kind, value = "a list", "[1.0, 2.0]"
            text = f"DATA:\n  - type: formula 2\n    wavelength_range: 0.3 0.9\n    coefficients: {value}\n"
        elif target == "wavelength_range":
            if kind == "a number":
                value = rng.choice(["0.5", "12"])
            text = f"DATA:\n  - type: formula 2\n    wavelength_range: {value}\n    coefficients: 0 1 0.1\n"
        else:
            text = f"{value}\n"
        field_name = {
            "DATA[0]": r"DATA\[0\]",
            "top": "DATA",
            "type": r"type|not supported",
            "data": r"`data`|rows",
            "wavelength_range": "wavelength_range",
        }.get(target, target)
        cases.append(yaml_upload("wrong_types", f"yaml-{target}-{kind}-{i}", text, field_name))
    json_wrong = [
        ("true", "a boolean"),
        ('"1.5"', "str"),
        ("null", "null"),
        ('{"a": 1}', "a map"),
        ("[[1], [2]]", "a list"),
        ('["a", "b"]', "str"),
        ("[null, 1]", "null"),
        ('[{"x": 1}, 2]', "a map"),
        ("5", "a number"),
    ]
    for i in range(20):
        field_name = rng.choice(["wavelength_nm", "n", "k", "name", "source"])
        value, _ = rng.choice(json_wrong)
        if field_name in ("name", "source") and (value.startswith('"') or value == "null"):
            value = rng.choice(["7", "[1]", "true"])  # text and null are legal there
        view = {"wavelength_nm": "[400, 500]", "n": "[1, 2]", "k": "[0, 0]", field_name: value}
        text = "{" + ", ".join(f'"{key}": {val}' for key, val in view.items()) + "}"
        cases.append(upload("wrong_types", f"json-file-{field_name}-{i}", text, "bad.json", field_name))
    body_wrong = [
        (f"{API}/fits", {"material": 5}, "material"),
        (f"{API}/fits", {"material": ["Au"]}, "material"),
        (f"{API}/fits", {"material": "Au", "eta_i_range": "1,2"}, "eta_i_range"),
        (f"{API}/fits", {"material": "Au", "eta_i_range": {"lo": 1}}, "eta_i_range"),
        (f"{API}/fits", {"material": "Au", "eta_i_range": [1, 2, 3]}, "eta_i_range"),
        (f"{API}/fits", {"material": "Au", "objective": 3}, "objective"),
        (f"{API}/fits", {"name": 12, "nk": GOOD_JSON}, "name"),
        (f"{API}/fits", {"name": "x", "nk": [1, 2, 3]}, "nk"),
        (f"{API}/fits", {"name": "x", "nk": {**GOOD_JSON, "n": "1 2 3"}}, r"nk\.n"),
        (f"{API}/fits", {"name": "x", "nk": {**GOOD_JSON, "n": ["1.5", "1", "1"]}}, r"nk\.n"),
        (f"{API}/fits", {"name": "x", "nk": {**GOOD_JSON, "k": [None, 1, 1]}}, r"nk\.k"),
        (f"{API}/fits", ["material", "Au"], "body"),
        (f"{API}/fits", "Au", "body"),
        (f"{API}/packs", {"fit_ids": "abc"}, "fit_ids"),
        (f"{API}/packs", {"fit_ids": [1, 2]}, "fit_ids"),
        (f"{API}/packs", {"fit_ids": ["0" * 32], "format": True}, "format"),
        (f"{API}/scenes", {"name": "s", "materials": {"a": 1}}, "materials"),
        (f"{API}/scenes", {"name": "s", "materials": [{"material": "Au", "eta_i": "1.5"}]}, "eta_i"),
        (f"{API}/fits/from-curves", {"curves": "none"}, "curves"),
        (f"{API}/fits/from-curves", {"curves": [{"eta_i": 1.5, "angle_deg": "0 90", "rgb": []}]}, "curves"),
    ]
    for i in range(3):  # thousands of unknown fields: refused in one error, cheaply
        extra = {f"x{j}": j for j in range(rng.randint(1_000, 50_000))}
        body_wrong.append(
            (
                rng.choice([f"{API}/fits", f"{API}/packs", f"{API}/scenes"]),
                {"material": "Au", **extra},
                r"extra fields are not permitted: \d+ unknown",
            )
        )
    for i, (path, value, expect) in enumerate(body_wrong):
        cases.append(json_body("wrong_types", f"json-body-{expect}-{i}", path, value, expect))
    return cases


def gen_yaml_tags(rng: random.Random) -> list[Case]:
    """Explicit tags and constructs that SafeLoader builds or refuses: never a 500, never an echo."""
    cases = []
    for i in range(24):
        size = rng.randint(100, 200_000)
        filler = ("".join(rng.choices("xyz0123456789", k=97)) * (size // 97 + 1))[:size]
        shape = rng.choice(
            [
                "python",
                "unknown",
                "float",
                "int",
                "timestamp",
                "binary",
                "documents",
                "unhashable",
                "big-int",
                "wrong-node",
                "long-anchor",
            ]
        )
        value = {
            "python": rng.choice(
                [
                    "!!python/object/apply:os.system ['true']",
                    "!!python/name:os.system ''",
                    "!!python/object:__main__.X {}",
                ]
            ),
            "unknown": f"!{filler[: rng.randint(1, 5000)]} x",
            "float": f"!!float {filler}",
            "int": f"!!int {filler}",
            "timestamp": rng.choice(["!!timestamp 2020-13-45", "!!timestamp 0000-00-00", "2020-02-31"]),
            # 4k + 1 base64 characters never decode
            "binary": f"!!binary '{filler[: len(filler) // 4 * 4]}a'",
            "documents": "x\n---\nDATA: []\n---\n" + "--- a\n" * rng.randint(1, 1000),
            "unhashable": "{? [a, b] : 1}",
            "big-int": "9" * rng.randint(4_301, 500_000),
            "wrong-node": rng.choice(
                ["!!str [1, 2]", "!!map [1]", "!!seq {a: 1}", "!!omap {a: 1}", "!!pairs [1]", "!!set [1]"]
            ),
            "long-anchor": f"[&{filler[:60_000]} 1, *{filler[:60_000]}]",
        }[shape]
        where = rng.choice(["REFERENCES", "data", "top"])
        if where == "REFERENCES":
            text = f"REFERENCES: {value}\nDATA:\n{GOOD_NK_ENTRY}"
        elif where == "data":
            text = f"DATA:\n  - type: tabulated nk\n    data: {value}\n"
        else:
            text = f"COMMENTS: {value}\nDATA:\n{GOOD_NK_ENTRY}"
        expect = r"YAML|REFERENCES|`data`|DATA|coverage|cover"
        cases.append(yaml_upload("yaml_tags", f"{shape}-{where}-{i}", text, expect))
    return cases


def gen_big_numbers(rng: random.Random) -> list[Case]:
    """Integer literals past Python's 4300-digit limit and floats past float64."""
    cases = []
    for i in range(12):
        digits = rng.randint(4_301, 400_000)
        literal = rng.choice(
            ["9" * digits, "-" + "1" * digits, "1" + "0" * digits + ".5", "1e" + "9" * rng.randint(3, 5000)]
        )
        field_name = rng.choice(["wavelength_nm", "n", "k"])
        nk = {key: json.dumps(v) for key, v in GOOD_JSON.items()}
        nk[field_name] = f"[{literal}, 1, 2]"
        nk_text = "{" + ", ".join(f'"{key}": {val}' for key, val in nk.items()) + "}"
        if rng.random() < 0.5:
            cases.append(
                upload("big_numbers", f"file-{field_name}-{i}", nk_text, "big.json", r"JSON|finite|float64|must be")
            )
        else:
            cases.append(
                body(
                    "big_numbers",
                    f"body-{field_name}-{i}",
                    f"{API}/fits",
                    f'{{"name": "x", "nk": {nk_text}}}',
                    r"parsed|finite|valid",
                )
            )
    return cases


def gen_booleans(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(16):
        nk = {key: list(values) for key, values in GOOD_JSON.items()}
        field_name = rng.choice(["wavelength_nm", "n", "k"])
        nk[field_name][rng.randrange(3)] = rng.choice([True, False])
        if rng.random() < 0.5:
            cases.append(
                json_body(
                    "booleans",
                    f"body-{field_name}-{i}",
                    f"{API}/fits",
                    {"name": "b", "nk": nk},
                    r"valid number|boolean",
                )
            )
        else:
            cases.append(
                upload(
                    "booleans",
                    f"file-{field_name}-{i}",
                    json.dumps(nk),
                    "b.json",
                    rf"`{field_name}\[\d\]` must be a number, got a boolean",
                )
            )
    extra = [
        (f"{API}/fits", {"material": "Au", "eta_i_range": [True, 2]}, "eta_i_range"),
        (f"{API}/fits", {"material": "Au", "eta_i_range": [1.2, False]}, "eta_i_range"),
        (f"{API}/scenes", {"name": "s", "materials": [{"material": "Au", "eta_i": True}]}, "eta_i"),
        (f"{API}/scenes", {"name": "s", "materials": [{"material": "Au", "eta_i": [1.5, True]}]}, "eta_i"),
        (f"{API}/scenes", {"name": "s", "materials": [{"material": "Au", "eta_i": {"min": True, "max": 2}}]}, "eta_i"),
        (
            f"{API}/fits/from-curves",
            {"curves": [{"eta_i": True, "angle_deg": [0, 45, 90], "rgb": [[0.5, 0.5, 0.5]] * 3}]},
            "eta_i",
        ),
        (
            f"{API}/fits/from-curves",
            {"curves": [{"eta_i": 1.5, "angle_deg": [0, True, 90], "rgb": [[0.5, 0.5, 0.5]] * 3}]},
            "angle_deg",
        ),
        (
            f"{API}/fits/from-curves",
            {"curves": [{"eta_i": 1.5, "angle_deg": [0, 45, 90], "rgb": [[0.5, True, 0.5]] * 3}]},
            "rgb",
        ),
    ]
    for i, (path, value, expect) in enumerate(extra):
        cases.append(json_body("booleans", f"body-{expect}-{i}", path, value, expect))
    return cases


def gen_non_finite(rng: random.Random) -> list[Case]:
    cases = []
    literals = ["NaN", "Infinity", "-Infinity", "1e999", "-1e400"]
    for i in range(16):
        literal = rng.choice(literals)
        field_name = rng.choice(["wavelength_nm", "n", "k"])
        values = {key: json.dumps(v) for key, v in GOOD_JSON.items()}
        numbers = list(GOOD_JSON[field_name])
        position = rng.randrange(3)
        values[field_name] = "[" + ", ".join(literal if j == position else str(v) for j, v in enumerate(numbers)) + "]"
        nk_text = "{" + ", ".join(f'"{key}": {val}' for key, val in values.items()) + "}"
        if rng.random() < 0.5:
            cases.append(
                body(
                    "non_finite",
                    f"body-{field_name}-{literal}-{i}",
                    f"{API}/fits",
                    f'{{"name": "x", "nk": {nk_text}}}',
                    r"finite",
                )
            )
        else:
            cases.append(
                upload("non_finite", f"file-{field_name}-{literal}-{i}", nk_text, "nan.json", r"finite|NaN|Infinity")
            )
    for i in range(6):
        literal = rng.choice([".nan", ".inf", "-.inf", "1e999", "nan", "inf", "-Infinity"])
        rows = GOOD_ROWS.splitlines()
        row = rng.randrange(len(rows))
        parts = rows[row].split()
        parts[rng.randrange(3)] = literal
        rows[row] = "        " + " ".join(parts)
        text = "DATA:\n  - type: tabulated nk\n    data: |\n" + "\n".join(rows) + "\n"
        cases.append(yaml_upload("non_finite", f"yaml-{literal}-{i}", text, r"finite|rows of numbers"))
    for i in range(6):
        literal = rng.choice(["nan", "inf", "-inf", "NaN", "1e999", "Infinity"])
        text = f"wavelength_nm,n,k\n400,1,1\n500,{literal},1\n600,1,1\n"
        cases.append(upload("non_finite", f"csv-{literal}-{i}", text, "nan.csv", r"finite"))
    eta = [
        '{"material": "Au", "eta_i_range": [NaN, 2]}',
        '{"material": "Au", "eta_i_range": [1, Infinity]}',
        '{"name": "s", "materials": [{"material": "Au", "eta_i": NaN}]}',
    ]
    for i, text in enumerate(eta):
        path = f"{API}/scenes" if "materials" in text else f"{API}/fits"
        cases.append(body("non_finite", f"body-eta-{i}", path, text, r"finite"))
    return cases


def streamed(data: bytes, chunk: int = 65_536):
    for start in range(0, len(data), chunk):
        yield data[start : start + chunk]


def gen_oversized(rng: random.Random) -> list[Case]:
    cases = []
    for i in range(6):
        size = rng.randint(BODY_LIMIT + 1, BODY_LIMIT * 3)
        filler = rng.choice(["a", "[", " ", "0"])
        text = ('{"material": "Au", "name": "' + filler * size + '"}').encode()
        path = rng.choice([f"{API}/fits", f"{API}/scenes", f"{API}/packs"])
        cases.append(body("oversized", f"body-{size}-{i}", path, text, r"at most \d+ bytes", statuses=(413,)))
    for i in range(4):
        size = rng.randint(BODY_LIMIT + 1, BODY_LIMIT * 2)
        data = b'{"material": "' + b"A" * size + b'"}'
        cases.append(
            Case(
                "oversized",
                f"body-chunked-{size}-{i}",
                "POST",
                f"{API}/fits",
                r"at most \d+ bytes",
                data,
                {"content": streamed(data), "headers": {"content-type": "application/json"}},
                statuses=(413,),
            )
        )
    for i in range(6):
        size = rng.randint(UPLOAD_LIMIT + 1, UPLOAD_LIMIT * 2)
        pattern = rng.choice([b"1,1,1\n", b"- ", b"[", b"\x00"])
        data = (pattern * (size // len(pattern) + 1))[:size]
        cases.append(
            upload(
                "oversized",
                f"upload-{size}-{i}",
                data,
                rng.choice(["big.csv", "big.yml", "big.json"]),
                r"at most \d+ bytes",
            )
        )
        cases[-1].statuses = (413,)
    return cases


def multipart(parts: list[tuple[bytes, bytes]], boundary: bytes, close: bool = True) -> bytes:
    out = b""
    for headers, content in parts:
        out += b"--" + boundary + b"\r\n" + headers + b"\r\n\r\n" + content + b"\r\n"
    return out + (b"--" + boundary + b"--\r\n" if close else b"")


def gen_malformed_multipart(rng: random.Random) -> list[Case]:
    cases = []
    good_file = b"wavelength_nm,n,k\n400,1,1\n500,1,1\n"
    file_headers = b'Content-Disposition: form-data; name="file"; filename="a.csv"'
    path = f"{API}/fits/upload"
    expect = r"multipart|boundary|file|field|body|parse|form"
    for i in range(22):
        boundary = "".join(rng.choice("abcdefXYZ0123456789-") for _ in range(rng.randint(1, 60))).encode()
        shape = rng.choice(
            [
                "no-boundary",
                "wrong-boundary",
                "truncated",
                "no-disposition",
                "no-file",
                "many-fields",
                "long-header",
                "garbage",
                "not-multipart",
                "empty",
                "header-no-colon",
            ]
        )
        ctype = b"multipart/form-data; boundary=" + boundary
        if shape == "no-boundary":
            data, ctype = multipart([(file_headers, good_file)], boundary), b"multipart/form-data"
        elif shape == "wrong-boundary":
            data = multipart([(file_headers, good_file)], boundary + b"x")
        elif shape == "truncated":
            full = multipart([(file_headers, good_file * 50)], boundary)
            data = full[: rng.randint(5, len(full) - 10)]
        elif shape == "no-disposition":
            data = multipart([(b"Content-Type: text/plain", good_file)], boundary)
        elif shape == "no-file":
            data = multipart([(b'Content-Disposition: form-data; name="format"', b"csv")], boundary)
        elif shape == "many-fields":
            count = rng.randint(1_100, 5_000)
            data = multipart(
                [(f'Content-Disposition: form-data; name="f{j}"'.encode(), b"v") for j in range(count)], boundary
            )
        elif shape == "long-header":
            data = multipart([(file_headers + b"; x=" + b"y" * rng.randint(10_000, 500_000), good_file)], boundary)
        elif shape == "garbage":
            data = rng.randbytes(rng.randint(1, 5_000))
        elif shape == "not-multipart":
            data, ctype = (
                good_file,
                rng.choice([b"text/plain", b"application/json", b"application/x-www-form-urlencoded"]),
            )
        elif shape == "empty":
            data = b""
        else:
            data = multipart([(b"this is not a header", good_file)], boundary)
        if len(data) > UPLOAD_LIMIT:
            continue
        cases.append(
            body("malformed_multipart", f"{shape}-{i}", path, data, expect, content_type=ctype.decode("latin-1"))
        )
    form_bad = [
        ({"eta_i_min": "abc"}, "eta_i_min"),
        ({"eta_i_max": "nan"}, "eta_i_max"),
        ({"eta_i_min": "true"}, "eta_i_min"),
        ({"eta_i_max": "1e999"}, "eta_i_max"),
        ({"format": "exe"}, "format"),
        ({"objective": "x" * 500}, "objective"),
        ({"name": " "}, "name"),
        ({"name": "n" * 5000}, "name"),
    ]
    for i, (form, expect) in enumerate(form_bad):
        cases.append(upload("malformed_multipart", f"form-{expect}-{i}", good_file, "a.csv", expect, **form))
    return cases


def gen_encoding(rng: random.Random) -> list[Case]:
    cases = []
    bad_sequences = [b"\xff\xfe", b"\xc0\xaf", b"\xed\xa0\x80", b"\xe9", b"\x80\x80", b"\xf8\x88\x80\x80\x80"]
    for i in range(16):
        fmt = rng.choice(["csv", "json", "yml"])
        base = {
            "csv": b"wavelength_nm,n,k\n400,1,1\n500,1,1\n",
            "json": json.dumps(GOOD_JSON).encode(),
            "yml": f"DATA:\n{GOOD_NK_ENTRY}".encode(),
        }[fmt]
        shape = rng.choice(["inject", "latin1", "utf16", "utf32", "random"])
        if shape == "inject":
            cut = rng.randrange(len(base))
            data = base[:cut] + rng.choice(bad_sequences) + base[cut:]
        elif shape == "latin1":
            data = base.replace(b"wavelength", "wavelength\u00e9".encode("latin-1"), 1)
            data = data if data != base else base + "\u00e9".encode("latin-1")
        elif shape == "utf16":
            data = base.decode().encode(rng.choice(["utf-16", "utf-16-le", "utf-16-be"]))
        elif shape == "utf32":
            data = base.decode().encode("utf-32")
        else:
            data = bytes(128 | b for b in rng.randbytes(rng.randint(1, 3_000)))
        cases.append(upload("encoding", f"{fmt}-{shape}-{i}", data, f"enc.{fmt}", r"UTF-8"))
    for i in range(6):
        text = json.dumps({"material": "Au", "name": "x"}).encode()
        cut = rng.randrange(1, len(text) - 1)
        data = text[:cut] + rng.choice(bad_sequences) + text[cut:]
        cases.append(body("encoding", f"body-{i}", f"{API}/fits", data, r"UTF-8|parsed|valid"))
    return cases


def gen_bom(rng: random.Random) -> list[Case]:
    cases = []
    bom = b"\xef\xbb\xbf"
    for i in range(10):
        shape = rng.choice(["yaml-references", "json-bool", "csv-header", "double-bom", "bom-only"])
        if shape == "yaml-references":
            data, name, expect = bom + f"REFERENCES: 12\nDATA:\n{GOOD_NK_ENTRY}".encode(), "b.yml", "REFERENCES"
        elif shape == "json-bool":
            nk = {**GOOD_JSON, "k": [True, 1, 1]}
            data, name, expect = bom + json.dumps(nk).encode(), "b.json", "boolean"
        elif shape == "csv-header":
            data, name, expect = bom + b"wavelength,n,k\n400,1,1\n500,1,1\n", "b.csv", "unit"
        elif shape == "double-bom":
            data, name, expect = bom + bom + json.dumps(GOOD_JSON).encode(), "b.json", "JSON|wavelength_nm"
        else:
            data, name, expect = bom, rng.choice(["b.csv", "b.json", "b.yml"]), r"empty|JSON|YAML|CSV"
        cases.append(upload("bom", f"{shape}-{i}", data, name, expect))
    for i in range(3):
        text = bom + json.dumps({"material": "Au", "eta_i_range": [True, 2]}).encode()
        cases.append(body("bom", f"body-{i}", f"{API}/fits", text, r"eta_i_range|parsed"))
    return cases


def gen_csv_hostile(rng: random.Random) -> list[Case]:
    cases = []
    header = "wavelength_nm,n,k\n"
    for i in range(18):
        shape = rng.choice(
            [
                "huge-field",
                "huge-header",
                "many-columns",
                "quoted-multiline",
                "blank-rows",
                "many-rows",
                "nul",
                "unterminated",
                "no-unit",
                "ragged",
            ]
        )
        if shape == "huge-field":
            text = header + "400," + "9" * rng.randint(1_001, 1_900_000) + ",1\n500,1,1\n"
        elif shape == "huge-header":
            text = "wavelength_nm," + "n" * rng.randint(1_001, 1_000_000) + ",k\n400,1,1\n"
        elif shape == "many-columns":
            columns = rng.randint(17, 50_000)
            text = header + ",".join(["1"] * columns) + "\n"
        elif shape == "quoted-multiline":
            text = header + '400,"' + "1\n" * rng.randint(600, 800_000) + '",1\n'
        elif shape == "blank-rows":
            text = header + "\n" * rng.randint(100_001, 1_900_000)
        elif shape == "many-rows":
            text = header + "".join(f"{300 + j / 1000:.3f},1,1\n" for j in range(rng.randint(100_001, 130_000)))
        elif shape == "nul":
            text = header + "400,1\x00,1\n500,1,1\n"
        elif shape == "unterminated":
            text = header + '400,"1,1\n500,1,1\n'
        elif shape == "no-unit":
            text = "wavelength," + "x" * rng.randint(100, 900) + ",k\n400,1,1\n"
        else:
            text = header + "400,1\n500,1,1,1\n"
        if len(text) > UPLOAD_LIMIT - 500:
            text = text[: UPLOAD_LIMIT - 500]
        cases.append(upload("csv_hostile", f"{shape}-{i}", text, "h.csv", r"CSV|finite|wavelength|column|UTF-8"))
    return cases


def gen_hostile_queries(rng: random.Random) -> list[Case]:
    """Query parameters and path ids out of range, of the wrong type, huge or non-finite."""
    cases = []
    for i in range(20):
        fit_id = "".join(rng.choice("0123456789abcdef") for _ in range(32))
        bad = rng.choice(["1e9", "-1", "nan", "inf", "true", "x" * rng.randint(1, 5000), "9" * 5000, ""])
        path, name = rng.choice(
            [
                (f"{API}/fits/{fit_id}/curves?samples={bad}", "samples"),
                (f"{API}/fits/{fit_id}/curves?eta_i={bad}", "eta_i"),
                (f"{API}/fits/{fit_id}/error-map?angles={bad}", "angles"),
                (f"{API}/fits/{fit_id}/error-map?rows={bad}", "rows"),
                (f"{API}/fits/{fit_id}/pack?format={bad}", "format"),
                (f"{API}/preview.png?fit={fit_id}&size={bad}", "size"),
                (f"{API}/preview.png?fit={fit_id}&eta_i={bad}", "eta_i"),
                (f"{API}/preview.png?fit={bad}", "fit"),
                (f"{API}/fits/{bad or 'x'}", "fit_id"),
            ]
        )
        cases.append(Case("hostile_queries", f"{name}-{i}", "GET", path, name, path.encode()))
    return cases


GENERATORS: list[Callable[[random.Random], list[Case]]] = [
    gen_yaml_alias_bomb,
    gen_deep_nesting,
    gen_huge_wavelength_range,
    gen_huge_samples,
    gen_wrong_types,
    gen_yaml_tags,
    gen_big_numbers,
    gen_booleans,
    gen_non_finite,
    gen_oversized,
    gen_malformed_multipart,
    gen_encoding,
    gen_bom,
    gen_csv_hostile,
    gen_hostile_queries,
]
CLASSES = [g.__name__.removeprefix("gen_") for g in GENERATORS]


@functools.lru_cache(maxsize=2)
def corpus(seed: int = SEED) -> tuple[Case, ...]:
    """Every generated case, shuffled; the same seed gives the same corpus."""
    rng = random.Random(seed)
    cases = [case for generator in GENERATORS for case in generator(rng)]
    rng.shuffle(cases)
    return tuple(cases)


# -- the run ---------------------------------------------------------------

POLLER = textwrap.dedent("""
    import json, sys, time, httpx
    url, stop, pid = sys.argv[1], sys.argv[2], sys.argv[3]
    import os
    def rss():
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024
    latencies, failures, peak = [], 0, 0.0
    with httpx.Client(timeout=5.0) as http:
        while not os.path.exists(stop):
            start = time.perf_counter()
            try:
                ok = http.get(url).status_code == 200
            except httpx.HTTPError:
                ok = False
            latencies.append(time.perf_counter() - start)
            failures += not ok
            peak = max(peak, rss())
            time.sleep(0.02)
    print(json.dumps({"latencies": latencies, "failures": failures, "peak_rss_mb": peak}))
""")


def memory_mb(pid: int) -> dict[str, float]:
    values = {}
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        key, _, rest = line.partition(":")
        if key in ("VmRSS", "VmHWM"):
            values[key] = int(rest.split()[0]) / 1024
    return values


@dataclass
class Answer:
    case: Case
    status: int | None
    content_type: str
    text: str
    seconds: float
    error: str | None = None


def send(http: httpx.Client, case: Case) -> Answer:
    start = time.perf_counter()
    try:
        response = http.request(case.method, case.path, **case.request)
    except httpx.HTTPError as error:
        return Answer(case, None, "", "", time.perf_counter() - start, f"{type(error).__name__}: {error}")
    return Answer(
        case, response.status_code, response.headers.get("content-type", ""), response.text, time.perf_counter() - start
    )


@pytest.fixture(scope="module")
def hostile_run(tmp_path_factory):
    data_dir = tmp_path_factory.mktemp("hostile") / "data"
    cases = corpus()
    stop = data_dir.parent / "stop"
    with server_process(data_dir) as server:
        with loopback.Client(base_url=server.url, timeout=10.0) as http:
            for _ in range(3):  # warm the routes before the baseline
                http.post(f"{API}/fits/upload", files={"file": ("w.csv", b"x")})
        before = memory_mb(server.process.pid)
        poller = subprocess.Popen(
            [sys.executable, "-c", POLLER, f"{server.url}/healthz", str(stop), str(server.process.pid)],
            stdout=subprocess.PIPE,
            text=True,
        )
        start = time.perf_counter()
        try:
            time.sleep(0.5)
            with loopback.Client(base_url=server.url, timeout=30.0) as http, ThreadPoolExecutor(CLIENTS) as pool:
                answers = list(pool.map(lambda case: send(http, case), cases))
        finally:
            stop.touch()
            polled = json.loads(poller.communicate(timeout=60)[0])
        seconds = time.perf_counter() - start
        after = memory_mb(server.process.pid)
        alive = server.process.poll() is None
    peak = after["VmHWM"] if after["VmHWM"] > before["VmHWM"] else before["VmRSS"]
    latencies = sorted(polled["latencies"])
    report = {
        "requests": len(answers),
        "seconds": seconds,
        "rss_before_mb": before["VmRSS"],
        "rss_after_mb": after["VmRSS"],
        "peak_growth_mb": max(peak, polled["peak_rss_mb"]) - before["VmRSS"],
        "healthz_polls": len(latencies),
        "healthz_failures": polled["failures"],
        "healthz_p50_s": latencies[len(latencies) // 2],
        "healthz_p99_s": latencies[min(len(latencies) - 1, int(0.99 * len(latencies)))],
        "healthz_max_s": latencies[-1],
        "server_alive": alive,
    }
    print("\nhostile run:", json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in report.items()}))
    return answers, report


def echoed(answer_text: str, payload: bytes) -> str | None:
    """A run of more than MAX_ECHO characters of the payload repeated in the answer, if any."""
    if len(answer_text) <= MAX_ECHO or len(payload) <= MAX_ECHO:
        return None
    haystack = payload.decode("utf-8", "replace")
    for start in range(len(answer_text) - MAX_ECHO):
        window = answer_text[start : start + MAX_ECHO + 1]
        if window in haystack:
            return window
    return None


def problems(answer: Answer) -> list[str]:
    case, found = answer.case, []
    if answer.status is None:
        return [f"no answer ({answer.error})"]
    if answer.status not in case.statuses:
        found.append(f"status {answer.status}, expected one of {case.statuses}")
    if not answer.content_type.startswith("application/json"):
        return found + [f"content-type {answer.content_type!r}: {answer.text[:100]!r}"]
    try:
        view = json.loads(answer.text)
    except ValueError:
        return found + [f"not JSON: {answer.text[:100]!r}"]
    detail = view.get("detail") if isinstance(view, dict) else None
    if not isinstance(detail, str) or not isinstance(view.get("errors"), list):
        return found + [f"not the error shape: {answer.text[:200]!r}"]
    if not re.search(case.expect, detail, re.IGNORECASE):
        found.append(f"message {detail[:200]!r} does not match /{case.expect}/")
    if len(answer.text) > 4_000:
        found.append(f"answer of {len(answer.text)} characters")
    repeat = echoed(answer.text, case.payload)
    if repeat:
        found.append(f"echoes {len(repeat)}+ characters of the input: {repeat[:40]!r}...")
    return found


def test_the_corpus_is_large_and_seeded():
    cases = corpus()
    assert len(cases) >= 250
    assert {case.klass for case in cases} == set(CLASSES)
    again = corpus.__wrapped__(SEED)
    assert [(c.label, c.payload) for c in again] == [(c.label, c.payload) for c in cases]
    assert [c.label for c in corpus(SEED + 1)] != [c.label for c in cases]


@pytest.mark.parametrize("klass", CLASSES)
def test_every_hostile_request_gets_a_clear_4xx(hostile_run, klass):
    answers, _ = hostile_run
    mine = [a for a in answers if a.case.klass == klass]
    assert mine
    failures = [f"{a.case.label}: {'; '.join(p)}" for a in mine if (p := problems(a))]
    assert not failures, f"{len(failures)} of {len(mine)} {klass} requests:\n" + "\n".join(failures[:20])


def test_server_survives_with_bounded_memory(hostile_run):
    _, report = hostile_run
    assert report["server_alive"]
    assert report["rss_after_mb"] - report["rss_before_mb"] < RSS_GROWTH_LIMIT_MB, report
    assert report["peak_growth_mb"] < RSS_GROWTH_LIMIT_MB, report


def test_healthz_stays_fast_during_the_run(hostile_run):
    _, report = hostile_run
    assert report["healthz_polls"] >= 20, report
    assert report["healthz_failures"] == 0, report
    assert report["healthz_p99_s"] < HEALTHZ_P99_LIMIT_S, report
